// libFuzzer target: glTF 2.0 through load_textured_mesh. An input starting with "glTF" is a GLB
// (written as mesh.glb, embedded buffers and images); otherwise [JSON] NUL [buffer bytes], written
// as mesh.gltf and mesh.bin (seeds use data: URIs or "uri": "mesh.bin").
#include <cstring>
#include "fuzz_loaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size >= 4 && std::memcmp(data, "glTF", 4) == 0) {
    fuzz::check_load_textured_mesh(fuzz::write_file("mesh.glb", {data, size}));
    return 0;
  }
  const auto parts = fuzz::split(data, size, 2);
  const std::string path = fuzz::write_file("mesh.gltf", parts[0]);
  fuzz::write_file("mesh.bin", parts[1]);
  fuzz::check_load_textured_mesh(path);
  return 0;
}
