#include "support/mesh_io.hpp"

#include "support/in_child.hpp"

#include <assimp/Importer.hpp>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <charconv>
#include <csignal>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <cstdint>
#include <cstdlib>
#include <vector>
#include <fstream>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>
#include <sys/wait.h>
#include <unistd.h>

namespace infolerp::support {

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
  if (!t) return in_mesh(t.error(), path);  // the message names the texture; say which asset wants it
  return std::shared_ptr<const texture>(std::make_shared<texture>(std::move(*t)));
}

// Appends an assimp mesh (triangles only) to `out`, with normals and texcoords when it has them.
// Texcoords that are not finite are set to (0, 0); returns how many.
std::size_t append_mesh(const aiMesh& mesh, indexed_mesh& out) {
  std::size_t non_finite = 0;
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
      const glm::vec2 uv{t.x, t.y};
      const bool finite = std::isfinite(uv.x) && std::isfinite(uv.y);
      non_finite += finite ? 0u : 1u;
      out.texcoords.push_back(finite ? uv : glm::vec2(0.0f));
    }
  }
  return non_finite;
}

// Refuses, before assimp allocates for them, sizes in a file's header that the file cannot hold
// (assimp trusts them): a PLY element count above one byte per property (one byte when it has
// none), a GLB chunk longer than what follows it. Other formats: no check.
status check_header_sizes(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  const bool ply = ext == ".ply" || ext == ".PLY", glb = ext == ".glb" || ext == ".GLB";
  if (!ply && !glb) return {};
  std::error_code error;
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  std::ifstream in(path, std::ios::binary);
  if (error || !in) return make_error(errc::bad_parameter, no_element, "cannot open mesh '", path, "'");
  auto too_large = [&](const auto&... what) {
    return make_error(errc::bad_parameter, no_element, "mesh '", path, "': the header's ", what..., " need more than the file's ", bytes,
                      " bytes");
  };
  if (glb) {  // 12-byte header (magic, version, length), then chunks of (length, type, data)
    std::uint32_t word[3] = {};
    if (!in.read(reinterpret_cast<char*>(word), 12)) return {};  // assimp names what is wrong
    if (word[2] > bytes) return too_large("length ", word[2]);
    for (std::uintmax_t at = 12; at + 8 <= bytes && in.read(reinterpret_cast<char*>(word), 8);) {
      if (word[0] > bytes - at - 8) return too_large("chunk of ", word[0], " bytes at ", at);
      at += 8 + word[0];
      in.seekg(static_cast<std::streamoff>(at));
    }
    return {};
  }
  std::uintmax_t needed = 0, count = 0, per_element = 0;
  auto close_element = [&] { needed += count * std::max<std::uintmax_t>(per_element, 1); };
  for (std::string line, key; std::getline(in, line) && line.rfind("end_header", 0) != 0;) {
    std::istringstream words(line);
    if (!(words >> key)) continue;
    if (key == "property") ++per_element;
    if (key != "element") continue;
    close_element();
    std::string name;
    count = 0;
    per_element = 0;
    if (!(words >> name >> count))
      return make_error(errc::bad_parameter, no_element, "mesh '", path, "': bad PLY header line '", line, "'");
    if (count > bytes) return too_large(count, " elements '", name, "'");
  }
  close_element();
  if (needed > bytes) return too_large("element counts");
  return {};
}

constexpr unsigned import_flags =
    aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices;

// The scene of an asset file: triangulated, identical vertices joined, node transforms applied
// (one mesh per node instance). An OFF file is read by read_off first, since assimp's OFF reader
// allocates what the header says. Errors name the file: sizes its header cannot hold, what
// read_off refuses, or what assimp could not read.
result<const aiScene*> import_scene(Assimp::Importer& importer, const std::string& path) {
  if (const std::string ext = std::filesystem::path(path).extension().string(); ext == ".off" || ext == ".OFF")
    if (auto m = read_off(path); !m) return m.error();
  if (auto s = check_header_sizes(path); !s) return s;
  const aiScene* scene = importer.ReadFile(path, import_flags);
  if (scene == nullptr)
    return make_error(errc::bad_parameter, no_element, "cannot load mesh '", path, "': ", importer.GetErrorString());
  return scene;
}

// The material names an OBJ file's material libraries define (`newmtl` of every `mtllib`), and
// the libraries that cannot be opened; empty for other formats. Assimp gives a material that
// `usemtl` names but no library defines the default properties, so only this tells them apart.
struct obj_libraries {
  bool obj = false;
  std::set<std::string> defined;
  std::vector<std::string> missing;
};
obj_libraries read_obj_libraries(const std::string& path) {
  obj_libraries libs;
  libs.obj = path.ends_with(".obj") || path.ends_with(".OBJ");
  if (!libs.obj) return libs;
  std::ifstream obj(path);
  for (std::string line; std::getline(obj, line);) {
    std::istringstream words(line);
    std::string key, name;
    if (!(words >> key) || key != "mtllib") continue;
    while (words >> name) {
      std::ifstream mtl(std::filesystem::path(path).parent_path() / name);
      if (!mtl) libs.missing.push_back(name);
      for (std::string entry; std::getline(mtl, entry);) {
        std::istringstream w(entry);
        if (std::string k, m; w >> k >> m && k == "newmtl") libs.defined.insert(m);
      }
    }
  }
  return libs;
}

// Why a part of an OBJ file has no material of its own: its `usemtl` name is in no library.
std::string undefined_material_note(const obj_libraries& libs, const std::string& material) {
  std::string why = "material '" + material + "' is defined in no material library";
  for (const auto& m : libs.missing) why += " ('" + m + "' cannot be opened)";
  return why + ": solid colour";
}

result<indexed_mesh> load_mesh_here(const std::string& path) {
  Assimp::Importer importer;
  const auto scene = import_scene(importer, path);
  if (!scene) return scene.error();
  indexed_mesh out;
  for (unsigned i = 0; i < (*scene)->mNumMeshes; ++i) append_mesh(*(*scene)->mMeshes[i], out);
  out.normals.clear();
  out.texcoords.clear();
  if (out.triangles.empty())
    return make_error(errc::empty_input, no_element, "mesh file '", path, "' holds no triangles");
  return out;
}

result<std::vector<textured_part>> load_textured_mesh_here(const std::string& path) {
  Assimp::Importer importer;
  const auto imported = import_scene(importer, path);
  if (!imported) return imported.error();
  const aiScene* scene = *imported;
  const obj_libraries libs = read_obj_libraries(path);
  std::vector<textured_part> parts;
  for (unsigned k = 0; k < std::max(scene->mNumMaterials, 1u); ++k) {
    textured_part part;
    bool texcoords = true, normals = true;
    std::size_t non_finite = 0;
    for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
      const aiMesh& mesh = *scene->mMeshes[i];
      if (mesh.mMaterialIndex != k && scene->mNumMaterials != 0) continue;
      texcoords = texcoords && mesh.HasTextureCoords(0);
      normals = normals && mesh.HasNormals();
      non_finite += append_mesh(mesh, part.mesh);
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
    else if (!part.image && libs.obj && part.material != AI_DEFAULT_MATERIAL_NAME && !libs.defined.contains(part.material))
      part.note = undefined_material_note(libs, part.material);
    else if (!part.image) part.note = "no diffuse texture: solid colour";
    if (texcoords && non_finite > 0)
      part.note += (part.note.empty() ? "" : "; ") + std::to_string(non_finite) + " texcoords not finite, set to (0, 0)";
    parts.push_back(std::move(part));
  }
  if (parts.empty()) return make_error(errc::empty_input, no_element, "mesh file '", path, "' holds no triangles");
  return parts;
}

// The loaders' results through run_in_child: an error as its code and message, a value field by field.
void put(byte_writer& out, const status& s) {
  out.put(s.code());
  out.put(std::string(bare_message(s)));
}
void put(byte_writer& out, const indexed_mesh& m) {
  out.put(m.positions);
  out.put(m.triangles);
  out.put(m.texcoords);
  out.put(m.normals);
}
status get(byte_reader& in, indexed_mesh& m) {
  in.get(m.positions);
  in.get(m.triangles);
  in.get(m.texcoords);
  in.get(m.normals);
  return {};
}
void put(byte_writer& out, const std::vector<textured_part>& parts) {
  out.put(parts.size());
  for (const auto& p : parts) {
    out.put(p.material);
    put(out, p.mesh);
    out.put(p.diffuse);
    out.put(p.note);
    const texture_level none;
    const texture_level& image = p.image ? p.image->level(0) : none;
    out.put(image.width);
    out.put(image.height);
    out.put(image.texels);
  }
}
status get(byte_reader& in, std::vector<textured_part>& parts) {
  std::size_t n = 0;
  in.get(n);
  for (std::size_t k = 0; k < n && in.good(); ++k) {
    textured_part& p = parts.emplace_back();
    in.get(p.material);
    if (auto s = get(in, p.mesh); !s) return s;
    in.get(p.diffuse);
    in.get(p.note);
    texture_level image;
    in.get(image.width);
    in.get(image.height);
    in.get(image.texels);
    if (image.texels.empty()) continue;
    auto t = texture::create(image.width, image.height, std::move(image.texels));
    if (!t) return t.error();
    p.image = std::make_shared<const texture>(std::move(*t));
  }
  return {};
}

// Runs load(path) in a child process (support/in_child.hpp) and returns its result here. The
// child gets 2 s plus 1 s per MB of the file, far above assimp's reading speed.
template <class T>
result<T> load_in_child(const std::string& path, result<T> (*load)(const std::string&)) {
  std::error_code error;
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  const auto limit = std::chrono::milliseconds(2000 + (error ? 0 : bytes / 1000));
  const child_result r = run_in_child(
      [&](byte_writer& out) {
        const result<T> value = load(path);
        out.put(value.ok());
        if (value) put(out, *value);
        else put(out, value.error());
      },
      limit);
  if (!r.completed)
    return make_error(errc::bad_parameter, no_element, "cannot load mesh '", path, "': the file is malformed (the reader died: ", r.death, ")");
  byte_reader in(r.bytes);
  bool ok = false;
  in.get(ok);
  T value;
  errc code = errc::ok;
  std::string message;
  if (ok) {
    if (auto s = get(in, value); !s) return s;
  } else {
    in.get(code);
    in.get(message);
  }
  if (!in.complete()) return make_error(errc::bad_parameter, no_element, "cannot load mesh '", path, "': the reader's result is incomplete");
  if (!ok) return make_error(code, no_element, message);
  return value;
}

}  // namespace

result<indexed_mesh> load_mesh(const std::string& path) { return load_in_child<indexed_mesh>(path, &load_mesh_here); }

result<std::vector<textured_part>> load_textured_mesh(const std::string& path) {
  return load_in_child<std::vector<textured_part>>(path, &load_textured_mesh_here);
}

namespace {

// Whitespace-separated tokens of an OFF file, '#' comments to the end of the line dropped; keeps
// the line number for messages and says whether more tokens remain on the current line.
class off_tokens {
 public:
  explicit off_tokens(std::istream& in) : in_(in) {}
  bool next(std::string& token) {
    while (!(line_ >> token)) {
      std::string text;
      if (!std::getline(in_, text)) return false;
      ++line_no_;
      if (const auto hash = text.find('#'); hash != std::string::npos) text.resize(hash);
      line_.clear();
      line_.str(text);
    }
    return true;
  }
  template <class T>
  bool integer(T& value) {
    std::string token;
    if (!next(token)) return false;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    return ec == std::errc{} && end == token.data() + token.size();
  }
  // The tokens left on the current line (consumed).
  std::vector<std::string> rest_of_line() {
    std::vector<std::string> rest;
    for (std::string token; line_ >> token;) rest.push_back(std::move(token));
    return rest;
  }
  std::size_t line_no() const { return line_no_; }

 private:
  std::istream& in_;
  std::istringstream line_;
  std::size_t line_no_ = 0;
};

// Appends face `n v0 .. v(n-1)` as a triangle fan.
void append_fan(const std::vector<std::uint32_t>& face, indexed_mesh& out) {
  for (std::size_t k = 2; k < face.size(); ++k) out.triangles.push_back({face[0], face[k - 1], face[k]});
}

// Reads tokens as whole faces (`n` then n indices, n >= 3), at most `limit` of them; false (and
// nothing appended) if they are not exactly that: then they are a colour, which OFF allows after
// a face's indices on its line.
bool parse_faces(const std::vector<std::string>& tokens, std::size_t limit, std::vector<std::vector<std::uint32_t>>& faces) {
  std::size_t i = 0;
  auto integer = [&](std::uint32_t& v) {
    if (i == tokens.size()) return false;
    const std::string& t = tokens[i++];
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    return ec == std::errc{} && end == t.data() + t.size();
  };
  faces.clear();
  while (i < tokens.size()) {
    std::uint32_t n = 0;
    if (faces.size() == limit || !integer(n) || n < 3 || n > tokens.size() - i) return false;
    auto& face = faces.emplace_back(n);
    for (auto& v : face)
      if (!integer(v)) return false;
  }
  return true;
}

}  // namespace

result<indexed_mesh> read_off(const std::string& path) {
  std::error_code size_error;
  const auto file_size = std::filesystem::file_size(path, size_error);
  std::ifstream in(path);
  if (!in || size_error) return make_error(errc::bad_parameter, no_element, "cannot open mesh '", path, "'");
  off_tokens tokens(in);
  auto fail = [&](const auto&... what) {
    return make_error(errc::bad_parameter, no_element, "mesh '", path, "' line ", tokens.line_no(), ": ", what...);
  };
  std::string header;
  if (!tokens.next(header) || header != "OFF") return fail("not an OFF file (expected the header 'OFF')");
  std::size_t nv = 0, nf = 0, ne = 0;
  if (!tokens.integer(nv) || !tokens.integer(nf) || !tokens.integer(ne)) return fail("expected the counts 'vertices faces edges'");
  // Every vertex is 3 tokens and every face at least 4, each token at least one character and
  // one separator: counts the file cannot hold are refused before anything is allocated.
  if (nv > file_size / 6 || nf > file_size / 8 || 6 * nv + 8 * nf > file_size + 1)
    return fail("the header's counts (", nv, " vertices, ", nf, " faces) need more than the file's ", file_size, " bytes");
  indexed_mesh out;
  out.positions.resize(nv);
  for (auto& p : out.positions) {
    std::string token;
    for (int c = 0; c < 3; ++c) {
      // strtof-compatible spellings (nan, inf) are read as such; validate_mesh rejects them.
      if (!tokens.next(token)) return fail("truncated vertex list");
      char* end = nullptr;
      p[c] = std::strtof(token.c_str(), &end);
      if (end != token.c_str() + token.size()) return fail("vertex coordinate is not a number");
    }
  }
  out.triangles.reserve(nf);
  std::vector<std::uint32_t> face;
  std::vector<std::vector<std::uint32_t>> more;
  for (std::size_t f = 0; f < nf;) {
    std::size_t n = 0;
    if (!tokens.integer(n)) return fail("truncated or non-numeric face list");
    if (n < 3) return fail("face with fewer than 3 vertices");
    if (n > file_size / 2) return fail("face of ", n, " vertices is longer than the file");
    face.clear();
    for (std::size_t k = 0; k < n; ++k)
      if (std::uint32_t v = 0; tokens.integer(v)) face.push_back(v);
      else return fail("truncated or non-numeric face list");
    append_fan(face, out);
    ++f;
    // OFF is free-form: what follows the indices on their line is more faces or a colour.
    if (!parse_faces(tokens.rest_of_line(), nf - f, more)) continue;
    for (const auto& g : more) append_fan(g, out);
    f += more.size();
  }
  if (out.triangles.empty()) return make_error(errc::empty_input, no_element, "mesh file '", path, "' holds no triangles");
  return out;
}

std::string_view bare_message(const status& s) {
  std::string_view text = s.message();
  if (text.starts_with("infolerp: ")) text.remove_prefix(10);
  return text;
}

status in_mesh(const status& s, const std::string& path) {
  return make_error(s.code(), s.element(), "mesh '", path, "': ", std::string(bare_message(s)));
}

std::string cgal_mesh(const std::string& name) { return std::string(INFOLERP_DATA_DIR) + "/" + name + ".off"; }

}  // namespace infolerp::support
