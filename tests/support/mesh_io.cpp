#include "support/mesh_io.hpp"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <charconv>
#include <filesystem>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <system_error>

namespace infolerp::support {

result<indexed_mesh> load_mesh(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
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

namespace {

// The diffuse (or glTF base colour) texture of a material: none (null), or loaded from the
// file next to the asset or from the image embedded in it.
result<std::shared_ptr<const texture>> material_texture(const aiScene& scene, const aiMaterial& mat, const std::string& path) {
  aiString name;
  if (mat.GetTexture(aiTextureType_DIFFUSE, 0, &name) != AI_SUCCESS &&
      mat.GetTexture(aiTextureType_BASE_COLOR, 0, &name) != AI_SUCCESS)
    return std::shared_ptr<const texture>{};
  const aiTexture* embedded = scene.GetEmbeddedTexture(name.C_Str());
  if (embedded != nullptr && embedded->mHeight != 0)
    return make_error(errc::bad_parameter, no_element, "'", path, "': uncompressed embedded texture '", name.C_Str(),
                      "' is not supported");
  auto t = embedded != nullptr
               ? decode_texture(std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(embedded->pcData), embedded->mWidth),
                                path + ":" + name.C_Str())
               : load_texture((std::filesystem::path(path).parent_path() / name.C_Str()).string());
  if (!t) return t.error();
  return std::shared_ptr<const texture>(std::make_shared<texture>(std::move(*t)));
}

// Appends an assimp mesh (triangles only) to `out`, with normals and texcoords when it has them.
void append_mesh(const aiMesh& mesh, indexed_mesh& out) {
  const auto base = static_cast<unsigned>(out.positions.size());
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    out.positions.push_back({mesh.mVertices[v].x, mesh.mVertices[v].y, mesh.mVertices[v].z});
    if (mesh.HasNormals()) out.normals.push_back({mesh.mNormals[v].x, mesh.mNormals[v].y, mesh.mNormals[v].z});
  }
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines
    out.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    if (!mesh.HasTextureCoords(0)) continue;
    for (unsigned c = 0; c < 3; ++c) {
      const aiVector3D& t = mesh.mTextureCoords[0][face.mIndices[c]];
      out.texcoords.push_back({t.x, t.y});
    }
  }
}

}  // namespace

result<std::vector<textured_part>> load_textured_mesh(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                                     aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices);
  if (scene == nullptr)
    return make_error(errc::bad_parameter, no_element, "cannot load mesh '", path, "': ", importer.GetErrorString());
  std::vector<textured_part> parts;
  for (unsigned k = 0; k < std::max(scene->mNumMaterials, 1u); ++k) {
    textured_part part;
    bool texcoords = true, normals = true;
    for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
      const aiMesh& mesh = *scene->mMeshes[i];
      if (mesh.mMaterialIndex != k && scene->mNumMaterials != 0) continue;
      texcoords = texcoords && mesh.HasTextureCoords(0);
      normals = normals && mesh.HasNormals();
      append_mesh(mesh, part.mesh);
    }
    if (part.mesh.triangles.empty()) continue;
    // Mixed meshes (some without texcoords or normals) keep neither, rather than a partial array.
    if (!texcoords) part.mesh.texcoords.clear();
    if (!normals) part.mesh.normals.clear();
    part.material = "material " + std::to_string(k);
    if (k < scene->mNumMaterials) {
      const aiMaterial& mat = *scene->mMaterials[k];
      if (aiString name; mat.Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length > 0) part.material = name.C_Str();
      aiColor4D c;
      if (mat.Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS || mat.Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
        part.diffuse = {c.r, c.g, c.b};
      auto image = material_texture(*scene, mat, path);
      if (!image) return image.error();
      part.image = std::move(*image);
    }
    if (!texcoords) part.note = "no texcoords: stretch channel skipped, solid colour";
    else if (!part.image) part.note = "no diffuse texture: solid colour";
    parts.push_back(std::move(part));
  }
  if (parts.empty()) return make_error(errc::empty_input, no_element, "mesh file '", path, "' holds no triangles");
  return parts;
}

result<indexed_mesh> read_off(const std::string& path) {
  std::ifstream in(path);
  if (!in) return make_error(errc::bad_parameter, no_element, "cannot open mesh '", path, "'");
  // Whitespace-separated tokens, '#' comments to the end of the line; counts the lines read.
  std::size_t line_no = 0;
  std::istringstream line;
  auto next = [&](std::string& token) {
    while (!(line >> token)) {
      std::string text;
      if (!std::getline(in, text)) return false;
      ++line_no;
      if (const auto hash = text.find('#'); hash != std::string::npos) text.resize(hash);
      line.clear();
      line.str(text);
    }
    return true;
  };
  auto fail = [&](const char* what) {
    return make_error(errc::bad_parameter, no_element, "mesh '", path, "' line ", line_no, ": ", what);
  };
  auto number = [&](auto& value) {
    std::string token;
    if (!next(token)) return false;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    return ec == std::errc{} && end == token.data() + token.size();
  };
  std::string header;
  if (!next(header) || header != "OFF") return fail("not an OFF file (expected the header 'OFF')");
  std::size_t nv = 0, nf = 0, ne = 0;
  if (!number(nv) || !number(nf) || !number(ne)) return fail("expected the counts 'vertices faces edges'");
  indexed_mesh out;
  out.positions.resize(nv);
  for (auto& p : out.positions) {
    std::string token;
    for (int c = 0; c < 3; ++c) {
      // strtof-compatible spellings (nan, inf) are read as such; validate_mesh rejects them.
      if (!next(token)) return fail("truncated vertex list");
      char* end = nullptr;
      p[c] = std::strtof(token.c_str(), &end);
      if (end != token.c_str() + token.size()) return fail("vertex coordinate is not a number");
    }
  }
  for (std::size_t f = 0; f < nf; ++f) {
    std::size_t n = 0;
    if (!number(n)) return fail("truncated or non-numeric face list");
    if (n < 3) return fail("face with fewer than 3 vertices");
    std::uint32_t first = 0, prev = 0;
    for (std::size_t k = 0; k < n; ++k) {
      std::uint32_t v = 0;
      if (!number(v)) return fail("truncated or non-numeric face list");
      if (k == 0) first = v;
      if (k >= 2) out.triangles.push_back({first, prev, v});
      prev = v;
    }
    line.str({});  // per-face colours after the indices are ignored
    line.clear();
  }
  if (out.triangles.empty()) return make_error(errc::empty_input, no_element, "mesh file '", path, "' holds no triangles");
  return out;
}

std::string cgal_mesh(const std::string& name) { return std::string(INFOLERP_DATA_DIR) + "/" + name + ".off"; }

}  // namespace infolerp::support
