# What `cmake --install build --prefix P` installs (and the Debian package, with P = /usr):
#   P/bin/vdmsim                         the program; it finds the files below relative to itself
#   P/lib/vdmsim/libvdmsim_assimp.so     the assimp module (meshes other than OBJ and PLY), opened on first use
#   P/share/vdmsim/scenes/, sweeps/, meshes/  the example scenes and sweep, the project's livers (the scenes' mesh
#                                        paths, ../meshes/..., hold there as in the source tree)
#   P/share/doc/vdmsim/                  README.md and the manual (docs/)
install(TARGETS vdmsim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS vdmsim_assimp LIBRARY DESTINATION ${VDMSIM_INSTALL_MODULE_DIR})
install(DIRECTORY assets/scenes assets/sweeps assets/meshes DESTINATION ${VDMSIM_INSTALL_DATA_DIR})
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)
