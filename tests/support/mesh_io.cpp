#include "support/mesh_io.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

namespace infolerp::support {

result<indexed_mesh> load_mesh(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr)
    return make_error(errc::bad_parameter, no_element, "cannot load mesh '", path, "': ", importer.GetErrorString());
  indexed_mesh out;
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh* mesh = scene->mMeshes[i];
    const auto base = static_cast<unsigned>(out.positions.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v)
      out.positions.push_back({mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z});
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      out.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  if (out.triangles.empty())
    return make_error(errc::empty_input, no_element, "mesh file '", path, "' holds no triangles");
  return out;
}

std::string cgal_mesh(const std::string& name) { return std::string(INFOLERP_DATA_DIR) + "/" + name + ".off"; }

}  // namespace infolerp::support
