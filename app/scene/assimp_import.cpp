// The vdmsim_assimp module (app/CMakeLists.txt): assimp's importer behind one C entry point,
// opened by app/scene/assimp_loader.cpp on the first mesh that needs it.
#include "app/scene/assimp_import.hpp"

#include <assimp/BaseImporter.h>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

namespace {

// Collects every triangle of every mesh node, in world coordinates.
void collect(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, std::vector<vdm::Vec3>& points,
             std::vector<std::array<int, 3>>& tris) {
  const aiMatrix4x4 world = parent * node->mTransformation;
  for (unsigned m = 0; m < node->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[m]];
    const int base = static_cast<int>(points.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D p = world * mesh->mVertices[v];
      points.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices < 3 || !face.mIndices) continue;  // points and lines carry no surface
      // Polygons as fans (0, k, k+1): assimp's own triangulation aborts on some malformed
      // faces (found by fuzzing). An index past this mesh's vertices becomes -1 (rejected later).
      auto index = [&](unsigned c) {
        return face.mIndices[c] < mesh->mNumVertices ? base + static_cast<int>(face.mIndices[c]) : -1;
      };
      for (unsigned k = 1; k + 1 < face.mNumIndices; ++k) tris.push_back({index(0), index(k), index(k + 1)});
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) collect(scene, node->mChildren[c], world, points, tris);
}

// assimp never reads PLY here (our reader does): its PLY importer is taken out of the importer.
void drop_assimp_ply(Assimp::Importer& importer) {
  if (Assimp::BaseImporter* ply = importer.GetImporter("ply")) {
    if (importer.UnregisterLoader(ply) == aiReturn_SUCCESS) delete ply;  // unregistering hands it back
  }
}

}  // namespace

extern "C" bool vdmsim_assimp_read(const char* path, std::vector<vdm::Vec3>* points,
                                   std::vector<std::array<int, 3>>* tris, std::string* error) {
  Assimp::Importer importer;
  drop_assimp_ply(importer);
  // Keep only positions and faces; weld identical vertices; do not let assimp "repair"
  // degenerate triangles: the checks after reading name them instead.
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS, aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                                          aiComponent_COLORS | aiComponent_TEXCOORDS |
                                                          aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                                          aiComponent_TEXTURES | aiComponent_LIGHTS |
                                                          aiComponent_CAMERAS | aiComponent_MATERIALS);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_ValidateDataStructure | aiProcess_RemoveComponent | aiProcess_JoinIdenticalVertices);
  if (!scene || !scene->mRootNode) {
    std::string why = importer.GetErrorString();
    if (why.empty()) why = "unknown reason";
    *error = "could not read the mesh (" + why + ")";
    return false;
  }
  collect(scene, scene->mRootNode, aiMatrix4x4(), *points, *tris);
  return true;
}
