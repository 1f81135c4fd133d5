// libFuzzer target: an OBJ with its material library and texture through load_textured_mesh.
// Input: [OBJ text] NUL [MTL text] NUL [image bytes], written as mesh.obj, mesh.mtl, texture.png
// (seeds name them with `mtllib mesh.mtl` and `map_Kd texture.png`).
#include "fuzz_loaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto parts = fuzz::split(data, size, 3);
  const std::string path = fuzz::write_file("mesh.obj", parts[0]);
  fuzz::write_file("mesh.mtl", parts[1]);
  fuzz::write_file("texture.png", parts[2]);
  fuzz::check_load_textured_mesh(path);
  return 0;
}
