// libFuzzer target: the I-Buffer upsampler with fuzzed image sizes, pass counts, options and
// cluster ids (background included), and the pass controller with fuzzed frame times.
// Input: [w][h][passes][max passes][rows per task][flags][cell][id count][ids...] then
// operations (render, set_passes, resize) and controller frame times.
// Checks: every pixel written and finite, R+I+E counts add up, passes = 1 equals per-pixel
// evaluation, a kept upsampler after resize/set_passes renders the same bits as a fresh one.
#include <cmath>
#include <cstring>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/upsample/pass_controller.hpp"
#include "infolerp/upsample/upsampler.hpp"
#include "reliability/reliability_support.hpp"

namespace {
using source = infolerp::reliability::table_source;
using up_t = infolerp::upsampler<source::sample_type>;

void render_and_check(up_t& up, const source& src) {
  const std::size_t pixels = std::size_t(up.width()) * up.height();
  const glm::vec3 poison(-1e30f);
  std::vector<glm::vec3> out(pixels, poison);
  FUZZ_CHECK(up.render(src, std::span<glm::vec3>(out)).ok());
  for (const auto& p : out) FUZZ_CHECK(p != poison && fuzz::finite(p));
  const auto& st = up.stats();
  const auto& last = st.pass[st.passes - 1];
  FUZZ_CHECK(last.width == up.width() && last.height == up.height());
  FUZZ_CHECK(last.evaluated + last.interpolated + last.reused == pixels);
  if (!up.kinds().empty()) FUZZ_CHECK(up.kinds().size() == pixels);
  if (up.passes() == 1) {  // plain evaluation
    for (std::uint32_t y = 0; y < up.height(); ++y)
      for (std::uint32_t x = 0; x < up.width(); ++x)
        FUZZ_CHECK(out[std::size_t(y) * up.width() + x] == src.shade(src.evaluate(x, y), x, y));
  }
  // A fresh one-shot upsampler with the same settings gives the same bits.
  std::vector<glm::vec3> fresh(pixels, poison);
  infolerp::upsampler_options o = up.options();
  FUZZ_CHECK(infolerp::upsample(src, up.width(), up.height(), std::span<glm::vec3>(fresh), o).ok());
  FUZZ_CHECK(std::memcmp(out.data(), fresh.data(), pixels * sizeof(glm::vec3)) == 0);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint32_t w = r.u16() % 160, h = r.u16() % 120;
  infolerp::upsampler_options o;
  o.passes = r.u8() % 18;
  o.max_passes = r.u8() % 18;
  o.rows_per_task = r.u8() % 9;
  const std::uint8_t flags = r.u8();
  o.record_kinds = flags & 1;
  o.keep_ibuffer = flags & 2;
  source src;
  src.cell = r.u8() % 17;
  std::vector<std::uint32_t> ids(r.u8() % 16);
  for (auto& id : ids) {
    const std::uint8_t b = r.u8();
    id = b == 255 ? infolerp::invalid_id : b == 254 ? r.u32() : b % 4;
  }
  src.ids = ids;

  auto up = up_t::create(w, h, o);
  fuzz::check_error(up.error());
  if (!up.ok()) return 0;
  render_and_check(*up, src);

  for (int op = 0; op < 4 && !r.empty(); ++op) {
    switch (r.u8() % 3) {
      case 0: {
        const std::uint32_t passes = r.u8() % 18, before = up->passes();
        const infolerp::status st = up->set_passes(passes);
        fuzz::check_error(st);
        FUZZ_CHECK(st.ok() ? up->passes() == passes : up->passes() == before);
        break;
      }
      case 1: {
        const std::uint32_t nw = r.u16() % 160, nh = r.u16() % 120, ow = up->width(), oh = up->height();
        const infolerp::status st = up->resize(nw, nh);
        fuzz::check_error(st);
        FUZZ_CHECK(st.ok() ? (up->width() == nw && up->height() == nh) : (up->width() == ow && up->height() == oh));
        break;
      }
      default: render_and_check(*up, src);
    }
  }

  infolerp::pass_controller_options co;
  co.min_frame_seconds = r.unit() * 0.05;
  co.max_frame_seconds = r.unit() * 0.1;
  co.max_passes = r.u8() % 18;
  co.initial_passes = r.u8() % 18;
  co.smoothing = r.unit();
  co.settle_frames = r.u8() % 5;
  co.forget_frames = r.u8();
  auto ctl = infolerp::pass_controller::create(co);
  fuzz::check_error(ctl.error());
  if (!ctl.ok()) return 0;
  while (!r.empty()) {
    const std::uint32_t before = ctl->passes();
    const infolerp::status st = ctl->update(r.unit() * 0.1);
    fuzz::check_error(st);
    if (!st.ok()) FUZZ_CHECK(ctl->passes() == before);
    FUZZ_CHECK(ctl->passes() >= 1 && ctl->passes() <= co.max_passes);
  }
  return 0;
}
