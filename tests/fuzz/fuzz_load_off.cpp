// libFuzzer target: OFF files (the input is the file) through read_off, which keeps the file's
// indices as written, and through assimp's OFF reader (load_mesh): never a crash, a leak or an
// allocation the file's size does not justify; errors name the file.
#include "fuzz_loaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write_file("mesh.off", {data, size});
  const auto m = infolerp::support::read_off(path);
  fuzz::check_error_names(m.error(), path);
  if (m) FUZZ_CHECK(!m->triangles.empty());
  fuzz::check_load_mesh(path);
  return 0;
}
