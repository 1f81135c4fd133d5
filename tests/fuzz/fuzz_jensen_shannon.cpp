// libFuzzer target: the checked information-theory API (jensen_shannon two-way and n-ary,
// checked_entropy, checked_mutual_information) on fuzzed distributions: zeros, subnormals,
// huge values, NaN/Inf, negative entries, mismatched sizes, weights outside [0, 1].
// Input: [mode][weight][bins][entries...]. Checks ranges, symmetry, float = double on
// float-representable input, agreement with a long-double reference, and js_estimate within
// its bound of the exact kernel on the normalised inputs.
#include <cmath>
#include <limits>
#include <span>
#include <vector>
#include "fuzz_common.hpp"
#include "infolerp/info/entropy.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/js_estimate.hpp"

namespace {
double entry(fuzz::reader& r) {
  const std::uint8_t s = r.u8();
  switch (s) {
    case 255: return r.take<double>();                           // raw bits
    case 254: return -static_cast<double>(r.u8());               // negative
    case 253: return std::ldexp(static_cast<double>(r.u8()), -1070);  // subnormal
    case 252: return std::ldexp(static_cast<double>(r.u8()), 1000);   // huge
    case 251: return static_cast<double>(r.take<float>());       // raw float bits
    default: return s < 64 ? 0.0 : static_cast<double>(s);       // many zero bins
  }
}

// Reference JS in long double from the normalised inputs (valid input only).
long double reference(const std::vector<double>& p, const std::vector<double>& q, double w) {
  long double sp = 0, sq = 0;
  for (double x : p) sp += x;
  for (double x : q) sq += x;
  long double sum = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const long double a = p[i] / sp, b = q[i] / sq, m = w * a + (1 - w) * b;
    if (a > 0 && w > 0) sum += w * a * std::log2(a / m);
    if (b > 0 && w < 1) sum += (1 - w) * b * std::log2(b / m);
  }
  return sum;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::reader r{data, size};
  const std::uint8_t mode = r.u8();
  const double w = r.unit();
  const std::size_t bins = r.u16() % 2048;
  const std::size_t bins_q = (mode & 1) ? bins : r.u16() % 2048;  // mismatched sizes sometimes
  std::vector<double> p(bins), q(bins_q);
  for (auto& x : p) x = entry(r);
  for (auto& x : q) x = entry(r);

  auto js = infolerp::jensen_shannon(std::span<const double>(p), std::span<const double>(q), w);
  fuzz::check_error(js.error());
  if (js.ok()) {
    FUZZ_CHECK(*js >= 0.0 && *js <= 1.0);
    auto back = infolerp::jensen_shannon(std::span<const double>(q), std::span<const double>(p), 1.0 - w);
    FUZZ_CHECK(back.ok());
    FUZZ_CHECK(std::abs(*back - *js) <= 1e-9);
    const long double ref = reference(p, q, w);
    FUZZ_CHECK(std::abs(static_cast<long double>(*js) - std::min<long double>(std::max<long double>(ref, 0), 1)) <= 1e-9L);
    auto self = infolerp::jensen_shannon(std::span<const double>(p), std::span<const double>(p), w);
    FUZZ_CHECK(self.ok() && *self == 0.0);
    // The estimate on the normalised rows (the clustering's precondition) is within its bound.
    auto normalised = [](std::vector<double> x) {
      long double sum = 0;
      for (double v : x) sum += v;
      for (double& v : x) v = static_cast<double>(v / sum);
      return x;
    };
    const auto pn = normalised(p), qn = normalised(q);
    const double exact = infolerp::js_divergence(std::span<const double>(pn), std::span<const double>(qn), w);
    const double est = infolerp::js_estimate(pn.data(), qn.data(), bins, w, infolerp::entropy_estimate(pn.data(), bins),
                                             infolerp::entropy_estimate(qn.data(), bins));
    FUZZ_CHECK(std::abs(est - exact) <= infolerp::js_estimate_error(bins));
  }
  // Float inputs: the float API equals the double API on the same (float-representable) values.
  // (Out-of-range doubles become ±Inf explicitly: a plain cast would be undefined behaviour.)
  const auto to_float = [](double x) -> float {
    constexpr double top = std::numeric_limits<float>::max();
    constexpr float inf = std::numeric_limits<float>::infinity();
    return x > top ? inf : x < -top ? -inf : static_cast<float>(x);
  };
  std::vector<float> pf, qf;
  for (double x : p) pf.push_back(to_float(x));
  for (double x : q) qf.push_back(to_float(x));
  std::vector<double> pd(pf.begin(), pf.end()), qd(qf.begin(), qf.end());
  auto jf = infolerp::jensen_shannon(std::span<const float>(pf), std::span<const float>(qf), w);
  auto jd = infolerp::jensen_shannon(std::span<const double>(pd), std::span<const double>(qd), w);
  fuzz::check_error(jf.error());
  FUZZ_CHECK(jf.ok() == jd.ok());
  if (jf.ok()) FUZZ_CHECK(*jf == *jd);
  else FUZZ_CHECK(jf.error().code() == jd.error().code());

  // n-ary: up to 4 distributions of p's size made from p, q and further bytes.
  const std::size_t k = 1 + (mode >> 1) % 4;
  std::vector<std::vector<double>> ds(k, p);
  for (std::size_t i = 1; i < k; ++i)
    for (auto& x : ds[i]) x = entry(r);
  std::vector<std::span<const double>> spans(ds.begin(), ds.end());
  std::vector<double> weights(k);
  for (auto& x : weights) x = r.unit();
  auto nary = infolerp::jensen_shannon(std::span<const std::span<const double>>(spans), std::span<const double>(weights));
  fuzz::check_error(nary.error());
  if (nary.ok()) FUZZ_CHECK(*nary >= 0.0 && *nary <= std::log2(static_cast<double>(k)));

  auto h = infolerp::checked_entropy(p);
  fuzz::check_error(h.error());
  if (h.ok()) FUZZ_CHECK(*h >= 0.0 && *h <= std::log2(static_cast<double>(p.size())) + 1e-9);
  // A channel: p(x) = first entries of q, rows = p.
  const std::size_t nx = q.empty() ? 0 : 1 + q.size() % 8;
  std::vector<double> px(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(std::min(nx, q.size())));
  auto mi = infolerp::checked_mutual_information(px, p);
  fuzz::check_error(mi.error());
  if (mi.ok()) {
    FUZZ_CHECK(std::isfinite(*mi) && *mi >= 0.0);
    auto ce = infolerp::checked_conditional_entropy(px, p);
    FUZZ_CHECK(ce.ok() && std::isfinite(*ce) && *ce >= 0.0);
    auto emi = infolerp::checked_element_mutual_information(px, p);
    FUZZ_CHECK(emi.ok() && emi->size() == px.size() && fuzz::all_finite(*emi));
  }
  return 0;
}
