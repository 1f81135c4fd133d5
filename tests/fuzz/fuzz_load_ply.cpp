// libFuzzer target: PLY files (the input is the file, ASCII or binary) through load_mesh and
// load_textured_mesh (texcoords, the TextureFile comment's texture).
#include "fuzz_loaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write_file("mesh.ply", {data, size});
  fuzz::check_load_mesh(path);
  fuzz::check_load_textured_mesh(path);
  return 0;
}
