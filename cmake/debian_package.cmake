# The Debian package: `cpack -G DEB` in the build folder writes vdmsim_VERSION_ARCH.deb with
# what cmake/install.cmake installs, under /usr. Its Depends come from dpkg-shlibdeps (dpkg-dev)
# run on the program and the assimp module; what vdmsim opens only when a feature needs it is
# recommended or suggested.
set(VDMSIM_PACKAGE_MAINTAINER "vdmsim maintainers <maintainers@users.noreply.h-seed-684f6b55.example>"
    CACHE STRING "The Debian package's Maintainer field")

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME vdmsim)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "vdmsim")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "soft-tissue surgical simulator (Volume Distribution Method)")
set(CPACK_PACKAGE_DESCRIPTION [=[vdmsim simulates soft organs for surgical training with the Volume
Distribution Method: an organ is its surface filled with an incompressible
fluid. Scenes are YAML files (an organ mesh, a material, what holds it,
probes and graspers on scripted timelines); vdmsim simulates them and draws
every frame offscreen as PNG images, with no display and no GPU. It also
reproduces the method's paper, calibrates materials against an FEM
reference, and compares images for golden-image tests.]=])
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)

set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # vdmsim_0.1.0_amd64.deb
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${VDMSIM_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The HUD's and the plots' font: without it the pictures use ImGui's built-in font.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "fonts-dejavu-core")
# gmsh is opened (dlopen) only for the FEM reference and `vdmsim calibrate`: recommend the
# package of the libgmsh built against; ffmpeg runs only for `vdmsim run --video`.
set(recommends "")
if(VDMSIM_GMSH_LIBRARY_FILE)
  execute_process(COMMAND dpkg -S "${VDMSIM_GMSH_LIBRARY_FILE}" OUTPUT_VARIABLE gmsh_owner ERROR_QUIET)
  if(gmsh_owner MATCHES "^([a-z0-9][a-z0-9.+-]*)[:,]")
    set(recommends "${CMAKE_MATCH_1}")
  endif()
endif()
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "${recommends}")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "ffmpeg, paraview")

include(CPack)
