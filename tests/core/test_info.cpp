// info/: Jensen–Shannon (two-way, weighted, n-ary, checked), log2, entropy and mutual
// information, against closed forms and a long double reference.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>
#include "infolerp/info/entropy.hpp"
#include "infolerp/info/jensen_shannon.hpp"
#include "infolerp/info/js_estimate.hpp"
#include "infolerp/info/log2.hpp"

namespace {
// Reference in long double, per bin, with log1p near 1 so that the reference itself is exact
// enough for p ≈ q.
long double log2_ref(long double x, long double m) {
  const long double d = x - m;
  return std::fabs(d) < m / 2 ? std::log1p(d / m) / std::log(2.0L) : std::log2(x / m);
}
template <class T>
long double js_ref(const std::vector<T>& p, const std::vector<T>& q, long double wp = 0.5L) {
  long double sp = 0, sq = 0, sum = 0, wq = 1 - wp;
  for (std::size_t i = 0; i < p.size(); ++i) {
    sp += p[i];
    sq += q[i];
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    const long double a = p[i] / sp, b = q[i] / sq, m = wp * a + wq * b;
    if (a > 0) sum += wp * a * log2_ref(a, m);
    if (b > 0) sum += wq * b * log2_ref(b, m);
  }
  return sum;
}
std::vector<double> random_distribution(std::size_t n, std::mt19937_64& rng, double zero_fraction = 0.0) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> p(n);
  double sum = 0.0;
  for (auto& x : p) {
    x = u(rng) < zero_fraction ? 0.0 : u(rng) * u(rng);
    sum += x;
  }
  if (sum == 0.0) p[0] = sum = 1.0;
  for (auto& x : p) x /= sum;
  return p;
}
double checked(infolerp::result<double> r) {
  REQUIRE(r.ok());
  return *r;
}
}  // namespace

TEST_CASE("log2_accurate matches long double to a few ulp") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-700.0, 700.0);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double x = std::exp2(u(rng));
    const double ref = static_cast<double>(std::log2(static_cast<long double>(x)));
    const double err = std::fabs(infolerp::detail::log2_accurate(x) - ref) / std::max(std::fabs(ref), 1e-300);
    worst = std::max(worst, err);
  }
  CHECK(worst < 1e-15);
  // Near 1, where log2 is tiny: relative accuracy must hold too.
  for (double d : {1e-15, 1e-10, 1e-5, 0.3, -1e-15, -1e-10, -0.25}) {
    const double x = 1.0 + d;
    const long double ref = std::log1p(static_cast<long double>(x) - 1.0L) / std::log(2.0L);
    CHECK(std::fabs(infolerp::detail::log2_accurate(x) - static_cast<double>(ref)) <= 4e-16 * std::fabs(static_cast<double>(ref)));
  }
  CHECK(infolerp::detail::log2_accurate(1.0) == 0.0);
  CHECK(infolerp::detail::log2_accurate(0.5) == -1.0);
  CHECK(infolerp::detail::log2_accurate(0x1p-1022) == -1022.0);
  // Outside the domain: finite, never NaN.
  for (double x : {0.0, 5e-324, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
    CHECK(std::isfinite(infolerp::detail::log2_accurate(x)));
}

TEST_CASE("JS closed forms: disjoint supports, identical, proportional, symmetry, weights") {
  const std::vector<double> a{0.5, 0.5, 0.0, 0.0}, b{0.0, 0.0, 0.25, 0.75};
  CHECK(infolerp::js_divergence(a, b) == Approx(1.0).margin(1e-15));
  CHECK(checked(infolerp::jensen_shannon(a, b)) == Approx(1.0).margin(1e-15));
  // Disjoint supports with weights (w, 1-w): JS = H(w) (binary entropy).
  for (double w : {0.1, 0.3, 0.9}) {
    const double h = -w * std::log2(w) - (1 - w) * std::log2(1 - w);
    CHECK(infolerp::js_divergence(a, b, w) == Approx(h).margin(1e-15));
  }
  CHECK(infolerp::js_divergence(a, a) == 0.0);
  CHECK(checked(infolerp::jensen_shannon(b, b, 0.3)) == 0.0);
  const std::vector<double> raw{3.0, 1.0, 7.0, 0.0, 2.5}, scaled{30.0, 10.0, 70.0, 0.0, 25.0};
  CHECK(checked(infolerp::jensen_shannon(raw, scaled)) < 1e-15);
  CHECK(checked(infolerp::jensen_shannon(raw, raw)) == 0.0);

  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const auto p = random_distribution(37, rng, 0.2), q = random_distribution(37, rng, 0.2);
    const double w = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    CHECK(infolerp::js_divergence(p, q, w) == Approx(infolerp::js_divergence(q, p, 1 - w)).margin(1e-15));
    CHECK(static_cast<double>(std::fabs(infolerp::js_divergence(p, q, w) - js_ref(p, q, w))) < 1e-12);
  }
  // Weight 0 or 1: no information, JS = 0.
  CHECK(infolerp::js_divergence(a, b, 0.0) == 0.0);
  CHECK(infolerp::js_divergence(a, b, 1.0) == 0.0);
  // js_channel: π₁ = p(a)/(p(a)+p(b)).
  CHECK(infolerp::js_channel(a, b, 1.0, 3.0) == Approx(infolerp::js_divergence(a, b, 0.25)).margin(1e-16));
  CHECK(infolerp::js_channel(a, b, 0.0, 0.0) == Approx(1.0).margin(1e-15));
}

TEST_CASE("JS: every length, every tail, against long double") {
  std::mt19937_64 rng(3);
  for (std::size_t n = 1; n <= 70; ++n) {
    const auto p = random_distribution(n, rng, 0.1), q = random_distribution(n, rng, 0.1);
    const double f = infolerp::js_divergence(p, q, 0.4);
    CHECK(std::fabs(f - static_cast<double>(js_ref(p, q, 0.4L))) < 1e-12);
  }
}

TEST_CASE("JS adversarial: subnormals, p == q up to the last bit, float32, a million bins") {
  std::mt19937_64 rng(5);
  SECTION("subnormal entries") {
    auto p = random_distribution(1000, rng), q = p;
    for (std::size_t i = 0; i < 1000; i += 3) p[i] = 4.9e-324 * static_cast<double>(i + 1);
    for (std::size_t i = 1; i < 1000; i += 7) q[i] = 1e-310;
    const double f = checked(infolerp::jensen_shannon(p, q));
    CHECK(std::isfinite(f));
    CHECK(std::fabs(f - static_cast<double>(js_ref(p, q))) < 1e-12);
    // Whole distributions of subnormals are normalised without overflow.
    const std::vector<double> tiny_p{5e-324, 1e-323, 0.0}, tiny_q{0.0, 1e-323, 5e-324};
    CHECK(checked(infolerp::jensen_shannon(tiny_p, tiny_q)) == Approx(static_cast<double>(js_ref(tiny_p, tiny_q))).margin(1e-12));
    const std::vector<double> huge_p{1.5e308, 1.5e308, 0.0}, huge_q{1.0, 1.0, 0.0};
    CHECK(checked(infolerp::jensen_shannon(huge_p, huge_q)) < 1e-15);
  }
  SECTION("p equal to q up to the last bit") {
    const auto p = random_distribution(4096, rng);
    auto q = p;
    for (std::size_t i = 0; i < q.size(); i += 2) q[i] = std::nextafter(q[i], 1.0);
    const double f = infolerp::js_divergence(p, q);
    CHECK(f >= 0.0);
    CHECK(std::fabs(f - static_cast<double>(js_ref(p, q))) < 1e-12);
    CHECK(f < 1e-14);  // the true value is ~1e-32; the rounding of m_i leaves ~1e-16 (documented)
  }
  SECTION("float32 inputs") {
    const auto pd = random_distribution(1001, rng, 0.1), qd = random_distribution(1001, rng, 0.1);
    std::vector<float> p(pd.begin(), pd.end()), q(qd.begin(), qd.end());
    CHECK(std::fabs(checked(infolerp::jensen_shannon(p, q, 0.7)) - static_cast<double>(js_ref(p, q, 0.7L))) < 1e-12);
    CHECK(std::isfinite(infolerp::js_divergence(p, q)));
  }
  SECTION("a million bins") {
    const auto p = random_distribution(1000003, rng, 0.05), q = random_distribution(1000003, rng, 0.05);
    CHECK(std::fabs(infolerp::js_divergence(p, q) - static_cast<double>(js_ref(p, q))) < 1e-12);
    CHECK(std::fabs(checked(infolerp::jensen_shannon(p, q, 0.2)) - static_cast<double>(js_ref(p, q, 0.2L))) < 1e-12);
  }
}

TEST_CASE("JS accuracy does not decay with the bin count: one-hot against uniform, weights 0.9/0.1") {
  // Closed form in long double: bin 0 has p = 1, q = 1/n; the other n - 1 bins p = 0, q = 1/n.
  const auto closed_form = [](std::size_t n, long double wp, long double wq) {
    const long double u = 1.0L / static_cast<long double>(n), m0 = wp + wq * u;
    return wp * std::log2(1.0L / m0) + wq * u * std::log2(u / m0) +
           static_cast<long double>(n - 1) * wq * u * std::log2(1.0L / wq);
  };
  // Every bin's term is >= 0 and JS is 0.47 here: about 18 roundings of it bound the summation.
  constexpr double tolerance = 1e-15;
  for (std::size_t n : {std::size_t{4096}, std::size_t{1} << 16, std::size_t{1} << 20}) {
    CAPTURE(n);
    std::vector<double> p(n, 0.0), q(n, 1.0 / static_cast<double>(n)), p3(n, 0.0), q_tenths(n, 0.1);
    p[0] = 1.0;
    p3[0] = 3.0;
    // The two-way kernel weighs q by 1 - 0.9 in double (exact, Sterbenz); the n-ary form by 0.1.
    const long double two_way = closed_form(n, 0.9L, 1.0L - 0.9L), n_ary = closed_form(n, 0.9L, 0.1L);
    CHECK(std::fabs(infolerp::js_divergence(p, q, 0.9) - static_cast<double>(two_way)) < tolerance);
    const std::vector<float> pf(p.begin(), p.end()), qf(q.begin(), q.end());
    CHECK(std::fabs(infolerp::js_divergence(pf, qf, 0.9) - static_cast<double>(two_way)) < tolerance);
    // Unnormalised input: the checked API's normalising sum of n entries 0.1 must be exact enough.
    CHECK(std::fabs(checked(infolerp::jensen_shannon(p3, q_tenths, 0.9)) - static_cast<double>(two_way)) < tolerance);
    const double w[] = {0.9, 0.1};
    const std::span<const double> normalised[] = {p, q}, unnormalised[] = {p3, q_tenths};
    CHECK(std::fabs(checked(infolerp::jensen_shannon(normalised, w)) - static_cast<double>(n_ary)) < tolerance);
    CHECK(std::fabs(checked(infolerp::jensen_shannon(unnormalised, w)) - static_cast<double>(n_ary)) < tolerance);
  }
}

TEST_CASE("JS kernel: the same bits on every ISA the dispatcher can pick") {
  // The portable kernel (SSE2 under GCC/Clang) against the AVX2 and AVX-512 copies the CPU
  // has: lengths 1..300 (every tail), float and double rows, scaled and unscaled, random
  // weights, zeros and equal bins.
  using namespace infolerp::detail;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> w(0.0, 1.0);
  std::size_t compared = 0;
  auto check = [&](const auto& p, const auto& q, double wp) {
    const auto* a = p.data();
    const auto* b = q.data();
    const std::size_t n = p.size();
    const double portable = js_kernel_on<js_vd, js_vu, false>(a, b, n, wp, 1.0, 1.0, 1.0, 1.0);
    const double scaled = js_kernel_on<js_vd, js_vu, true>(a, b, n, wp, 0x1p-3, 8.0, 2.0, 0.5);
    auto same = [&](double unscaled_bits, double scaled_bits) {
      REQUIRE(unscaled_bits == portable);
      REQUIRE(scaled_bits == scaled);
      ++compared;
    };
    (void)same;
#ifdef INFOLERP_JS_AVX2
    if (x86_vector_level() >= 1)
      same(js_kernel_avx2<false>(a, b, n, wp, 1.0, 1.0, 1.0, 1.0), js_kernel_avx2<true>(a, b, n, wp, 0x1p-3, 8.0, 2.0, 0.5));
#endif
#ifdef INFOLERP_JS_AVX512
    if (x86_vector_level() == 2)
      same(js_kernel_avx512<false>(a, b, n, wp, 1.0, 1.0, 1.0, 1.0), js_kernel_avx512<true>(a, b, n, wp, 0x1p-3, 8.0, 2.0, 0.5));
#endif
  };
  for (std::size_t n = 1; n <= 300; ++n) {
    auto p = random_distribution(n, rng, 0.2), q = random_distribution(n, rng, 0.2);
    for (std::size_t i = 0; i < n; i += 5) q[i] = p[i];  // equal bins contribute exactly 0
    const double wp = w(rng);
    check(p, q, wp);
    check(std::vector<float>(p.begin(), p.end()), std::vector<float>(q.begin(), q.end()), wp);
  }
  if (compared == 0) WARN("no AVX2 or AVX-512 kernel on this build or CPU: only the portable one ran");
}

TEST_CASE("log2 estimate: every float in [sqrt(1/2), sqrt(2)) within log2_estimate_error, every variant") {
  // Exhaustive over the reduced range (8.4 million floats): the portable polynomial, the
  // dispatched one and each AVX2+FMA / AVX-512 copy the CPU can run, against long double.
  using namespace infolerp::detail;
  std::vector<float> x;
  for (std::uint32_t bits = 0x3F3504F3u; bits < 0x3FB504F4u; ++bits) {
    float f;
    std::memcpy(&f, &bits, sizeof f);
    if (f >= static_cast<float>(std::sqrt(0.5L)) && f < static_cast<float>(std::sqrt(2.0L))) x.push_back(f);
  }
  while (x.size() % 8) x.push_back(1.0f);
  std::vector<float> dispatched(x.size()), portable(x.size());
  log2_estimate(x.data(), dispatched.data(), x.size());
  CHECK(log2_estimate_from<jse_vf, jse_vi>(x.data(), portable.data(), 0, x.size()) == x.size());
  auto worst = [&](const std::vector<float>& l) {
    long double w = 0;
    for (std::size_t i = 0; i < x.size(); ++i) w = std::max(w, std::fabs(l[i] - std::log2(static_cast<long double>(x[i]))));
    return w;
  };
  const long double worst_d = worst(dispatched), worst_p = worst(portable);
  INFO("worst dispatched " << static_cast<double>(worst_d) << ", portable " << static_cast<double>(worst_p));
  CHECK(x.size() > 8000000);
  CHECK(worst_d <= infolerp::log2_estimate_error);
  CHECK(worst_p <= infolerp::log2_estimate_error);
  // Each compiled copy the CPU can run, not only the one dispatched.
  std::vector<float> other(x.size());
#ifdef INFOLERP_JSE_AVX2
  if (x86_vector_level() >= 1) {
    log2_estimate_avx2(x.data(), other.data(), x.size());
    CHECK(static_cast<double>(worst(other)) <= infolerp::log2_estimate_error);
  }
#endif
#ifdef INFOLERP_JSE_AVX512
  if (x86_vector_level() == 2) {
    log2_estimate_avx512(x.data(), other.data(), x.size());
    CHECK(static_cast<double>(worst(other)) <= infolerp::log2_estimate_error);
  }
#endif
  CHECK(worst_p > 1e-8);  // the bound is not loose by orders of magnitude
  // Outside the reduced range: the exponent is exact, zero and subnormals stay finite.
  std::vector<float> y{1.0f, 2.0f, 0.5f, 1e-30f, 3e30f, 0.0f, 1e-40f, 1.17e-38f}, ly(8);
  log2_estimate(y.data(), ly.data(), 8);
  for (std::size_t i = 0; i < 5; ++i) CHECK(std::fabs(ly[i] - std::log2(static_cast<double>(y[i]))) <= 4e-6);
  for (float l : ly) CHECK(std::isfinite(l));
  CHECK(0.0f * ly[5] == 0.0f);
}

TEST_CASE("JS estimate: within js_estimate_error of the exact kernel on every shape of row") {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_ratio = 0.0;
  auto check = [&](const auto& p, const auto& q, double wp) {
    const std::size_t n = p.size();
    const double exact = infolerp::js_divergence(p, q, wp);
    const double est = infolerp::js_estimate(p.data(), q.data(), n, wp, infolerp::entropy_estimate(p.data(), n),
                                             infolerp::entropy_estimate(q.data(), n));
    const double bound = infolerp::js_estimate_error(n);
    INFO("n " << n << ", wp " << wp << ", exact " << exact << ", estimate " << est);
    REQUIRE(std::fabs(est - exact) <= bound);
    REQUIRE(est >= 0.0);
    REQUIRE(est <= 1.0);
    worst_ratio = std::max(worst_ratio, std::fabs(est - exact) / bound);
    // The same estimate through each compiled copy of the kernel, not only the dispatched one.
    using T = typename std::decay_t<decltype(p)>::value_type;
    const auto through = [&](auto sum) {
      const double h = -sum(p.data(), q.data(), n, static_cast<float>(wp), static_cast<float>(1.0 - wp));
      const double hp = -sum(p.data(), nullptr, n, 1.0f, 0.0f), hq = -sum(q.data(), nullptr, n, 1.0f, 0.0f);
      REQUIRE(std::fabs(std::clamp(h - (wp * hp + (1.0 - wp) * hq), 0.0, 1.0) - exact) <= bound);
    };
    through(infolerp::detail::xlogx_sum_on<infolerp::detail::jse_vf, infolerp::detail::jse_vi, T>);
#ifdef INFOLERP_JSE_AVX2
    if (infolerp::detail::x86_vector_level() >= 1) through(infolerp::detail::xlogx_sum_avx2<T>);
#endif
#ifdef INFOLERP_JSE_AVX512
    if (infolerp::detail::x86_vector_level() == 2) through(infolerp::detail::xlogx_sum_avx512<T>);
#endif
  };
  for (std::size_t n : {1u, 2u, 7u, 8u, 15u, 16u, 17u, 63u, 64u, 65u, 257u, 1000u, 4096u}) {
    for (int trial = 0; trial < 40; ++trial) {
      const double wp = trial % 10 == 0 ? 0.0 : trial % 10 == 1 ? 1.0 : u(rng);
      auto p = random_distribution(n, rng, trial % 3 * 0.3), q = random_distribution(n, rng, trial % 2 * 0.5);
      if (trial % 5 == 2) q = p;  // identical: JS 0
      if (trial % 5 == 3)         // nearly identical
        for (auto& x : q) x = std::nextafter(x, 1.0);
      check(p, q, wp);
      check(std::vector<float>(p.begin(), p.end()), std::vector<float>(q.begin(), q.end()), wp);
    }
    // One-hot rows on different bins (JS = h(wp)), and a row of subnormal-sized entries.
    std::vector<double> a(n, 0.0), b(n, 0.0);
    a[0] = 1.0;
    b[n - 1] += 1.0;
    check(a, b, 0.5);
    check(a, b, 0.2);
    if (n > 2) {
      auto c = random_distribution(n, rng);
      double sum = 0.0;
      for (std::size_t i = 0; i < n; ++i) sum += (c[i] = i % 2 ? c[i] : 1e-39);
      for (auto& x : c) x /= sum;
      check(c, a, 0.5);
      check(std::vector<float>(c.begin(), c.end()), std::vector<float>(a.begin(), a.end()), 0.5);
    }
  }
  INFO("worst |estimate - exact| / bound " << worst_ratio);
  CHECK(worst_ratio < 1.0);
}

TEST_CASE("JS checked API: clear errors naming the bin") {
  const std::vector<double> good{0.25, 0.75}, three{0.2, 0.3, 0.5};
  CHECK(infolerp::jensen_shannon(good, three).error().code() == infolerp::errc::bad_distribution);
  CHECK(infolerp::jensen_shannon(std::span<const double>{}, std::span<const double>{}).error().code() == infolerp::errc::empty_input);
  for (double w : {-0.1, 1.5, std::numeric_limits<double>::quiet_NaN()})
    CHECK(infolerp::jensen_shannon(good, good, w).error().code() == infolerp::errc::bad_parameter);
  const std::vector<double> nan{0.5, std::numeric_limits<double>::quiet_NaN(), 0.5};
  auto r = infolerp::jensen_shannon(three, nan);
  CHECK(r.error().code() == infolerp::errc::non_finite);
  CHECK(r.error().element() == 1);
  CHECK(r.error().message().find("q bin 1") != std::string::npos);
  const std::vector<double> inf{std::numeric_limits<double>::infinity(), 0.0, 1.0};
  CHECK(infolerp::jensen_shannon(inf, three).error().code() == infolerp::errc::non_finite);
  const std::vector<double> negative{0.5, 0.6, -0.1};
  r = infolerp::jensen_shannon(negative, three);
  CHECK(r.error().code() == infolerp::errc::bad_distribution);
  CHECK(r.error().element() == 2);
  CHECK(r.error().message().find("p bin 2") != std::string::npos);
  const std::vector<double> zeros{0.0, 0.0, 0.0};
  r = infolerp::jensen_shannon(three, zeros);
  CHECK(r.error().code() == infolerp::errc::bad_distribution);
  CHECK(r.error().message().find("all 3 bins are zero") != std::string::npos);
  const std::vector<float> fz{0.0f, 0.0f};
  CHECK(infolerp::jensen_shannon(fz, fz).error().code() == infolerp::errc::bad_distribution);
}

TEST_CASE("n-ary JS: agrees with the two-way form, closed forms, errors") {
  std::mt19937_64 rng(11);
  const auto p = random_distribution(300, rng, 0.1), q = random_distribution(300, rng, 0.1);
  const std::span<const double> two[] = {p, q};
  const double w2[] = {0.3, 0.7};
  CHECK(checked(infolerp::jensen_shannon(two, w2)) == Approx(infolerp::js_divergence(p, q, 0.3)).margin(1e-14));
  // Unnormalised weights are normalised.
  const double w2x[] = {3.0, 7.0};
  CHECK(checked(infolerp::jensen_shannon(two, w2x)) == Approx(infolerp::js_divergence(p, q, 0.3)).margin(1e-14));
  // n disjoint distributions with equal weights: log2 n bits; all alike: 0.
  std::vector<std::vector<double>> disjoint(5, std::vector<double>(5, 0.0));
  std::vector<std::span<const double>> views;
  for (std::size_t i = 0; i < 5; ++i) {
    disjoint[i][i] = 2.0;
    views.emplace_back(disjoint[i]);
  }
  const std::vector<double> equal(5, 1.0);
  CHECK(checked(infolerp::jensen_shannon(views, equal)) == Approx(std::log2(5.0)).margin(1e-14));
  const std::span<const double> same[] = {p, p, p};
  const double w3[] = {1.0, 2.0, 3.0};
  CHECK(checked(infolerp::jensen_shannon(same, w3)) == 0.0);
  // n-ary against a long double reference with random weights.
  const auto r = random_distribution(300, rng, 0.3);
  const std::span<const double> three[] = {p, q, r};
  const double w[] = {0.2, 0.5, 0.3};
  long double ref = 0;
  for (std::size_t y = 0; y < 300; ++y) {
    const long double m = 0.2L * p[y] + 0.5L * q[y] + 0.3L * r[y];
    const long double x[] = {p[y], q[y], r[y]};
    for (int i = 0; i < 3; ++i)
      if (x[i] > 0) ref += w[i] * x[i] * log2_ref(x[i], m);
  }
  CHECK(std::fabs(checked(infolerp::jensen_shannon(three, w)) - static_cast<double>(ref)) < 1e-12);
  // Errors.
  CHECK(infolerp::jensen_shannon(std::span<const std::span<const double>>{}, std::span<const double>{}).error().code() ==
        infolerp::errc::empty_input);
  CHECK(infolerp::jensen_shannon(three, w2).error().code() == infolerp::errc::bad_size);
  const double bad_w[] = {0.2, -0.5, 0.3};
  auto e = infolerp::jensen_shannon(three, bad_w);
  CHECK(e.error().code() == infolerp::errc::bad_parameter);
  CHECK(e.error().element() == 1);
  const double zero_w[] = {0.0, 0.0, 0.0};
  CHECK(infolerp::jensen_shannon(three, zero_w).error().code() == infolerp::errc::bad_parameter);
  // Finite weights whose sum overflows are valid weights: 3:1 and 1:1 as the two-way form.
  constexpr double huge = std::numeric_limits<double>::max();
  const double w_huge[] = {huge, huge / 3}, w_equal_huge[] = {huge, huge};
  CHECK(checked(infolerp::jensen_shannon(two, w_huge)) == Approx(infolerp::js_divergence(p, q, 0.75)).margin(1e-14));
  CHECK(checked(infolerp::jensen_shannon(two, w_equal_huge)) == Approx(infolerp::js_divergence(p, q, 0.5)).margin(1e-14));
  // Messages print numbers in shortest form.
  const double w_big_negative[] = {1e300, -1e300};
  e = infolerp::jensen_shannon(two, w_big_negative);
  CHECK(e.error().code() == infolerp::errc::bad_parameter);
  CHECK(e.error().message() == "infolerp: jensen_shannon: weight 1 is -1e+300 (must be finite and >= 0)");
  const std::vector<double> shorter(299, 1.0);
  const std::span<const double> mismatched[] = {p, shorter};
  CHECK(infolerp::jensen_shannon(mismatched, w2).error().element() == 1);
  std::vector<double> has_nan = p;
  has_nan[17] = std::numeric_limits<double>::quiet_NaN();
  const std::span<const double> with_nan[] = {p, has_nan};
  e = infolerp::jensen_shannon(with_nan, w2);
  CHECK(e.error().code() == infolerp::errc::non_finite);
  CHECK(e.error().element() == 17);
  CHECK(e.error().message().find("distribution 1 bin 17") != std::string::npos);
}

TEST_CASE("entropy, conditional entropy, mutual information: closed forms") {
  const std::vector<double> uniform4(4, 0.25), certain{0.0, 1.0, 0.0};
  CHECK(infolerp::entropy(uniform4) == Approx(2.0).margin(1e-15));
  CHECK(infolerp::entropy(certain) == 0.0);
  CHECK(checked(infolerp::checked_entropy(std::vector<double>{1.0, 1.0, 1.0, 1.0, 0.0})) == Approx(2.0).margin(1e-15));
  const std::vector<double> biased{0.1, 0.9};
  CHECK(infolerp::entropy(biased) == Approx(-0.1 * std::log2(0.1) - 0.9 * std::log2(0.9)).margin(1e-15));

  // Noiseless channel (identity): I(X;Y) = H(X), H(Y|X) = 0, I(x;Y) = -log2 p(x).
  const std::vector<double> px{0.5, 0.25, 0.25};
  const std::vector<double> identity{1, 0, 0, 0, 1, 0, 0, 0, 1};
  CHECK(infolerp::mutual_information(px, identity) == Approx(1.5).margin(1e-15));
  CHECK(infolerp::conditional_entropy(px, identity) == 0.0);
  auto per = infolerp::checked_element_mutual_information(px, identity);
  REQUIRE(per.ok());
  CHECK((*per)[0] == Approx(1.0).margin(1e-15));
  CHECK((*per)[1] == Approx(2.0).margin(1e-15));
  // Useless channel (all rows alike): I = 0 exactly, H(Y|X) = H(Y).
  const std::vector<double> alike{0.2, 0.8, 0.2, 0.8, 0.2, 0.8};
  CHECK(infolerp::mutual_information(px, alike) == 0.0);
  CHECK(infolerp::conditional_entropy(px, alike) == Approx(infolerp::entropy(std::vector<double>{0.2, 0.8})).margin(1e-15));
  // Binary symmetric channel with crossover e, uniform input: I = 1 - H(e).
  const double e = 0.11;
  const std::vector<double> bsc{1 - e, e, e, 1 - e}, half{0.5, 0.5};
  const double he = -e * std::log2(e) - (1 - e) * std::log2(1 - e);
  CHECK(infolerp::mutual_information(half, bsc) == Approx(1 - he).margin(1e-15));
  CHECK(infolerp::conditional_entropy(half, bsc) == Approx(he).margin(1e-15));
  // I(X;Y) = Σ p(x) I(x;Y) and H(Y) = H(Y|X) + I(X;Y) on a random channel.
  std::mt19937_64 rng(9);
  const auto p = random_distribution(20, rng, 0.2);
  std::vector<double> rows;
  for (int x = 0; x < 20; ++x) {
    const auto row = random_distribution(30, rng, 0.3);
    rows.insert(rows.end(), row.begin(), row.end());
  }
  const double mi = checked(infolerp::checked_mutual_information(p, rows));
  const auto py = infolerp::output_distribution(p, rows);
  CHECK(infolerp::entropy(py) == Approx(infolerp::conditional_entropy(p, rows) + mi).margin(1e-13));
  auto each = infolerp::checked_element_mutual_information(p, rows);
  REQUIRE(each.ok());
  double sum = 0.0;
  for (std::size_t x = 0; x < 20; ++x) {
    CHECK((*each)[x] >= 0.0);
    sum += p[x] * (*each)[x];
  }
  CHECK(sum == Approx(mi).margin(1e-14));
  // Near-identical rows: per-term forms stay >= 0 where H(Y) - H(Y|X) would cancel.
  std::vector<double> close = rows;
  for (int x = 0; x < 20; ++x) std::copy(rows.begin(), rows.begin() + 30, close.begin() + x * 30);
  close[31] = std::nextafter(close[31], 1.0);
  CHECK(infolerp::mutual_information(p, close) >= 0.0);
  CHECK(infolerp::mutual_information(p, close) < 1e-14);
}

TEST_CASE("entropy checked variants: errors") {
  CHECK(infolerp::checked_entropy(std::vector<double>{}).error().code() == infolerp::errc::empty_input);
  CHECK(infolerp::checked_entropy(std::vector<double>{0.0, 0.0}).error().code() == infolerp::errc::bad_distribution);
  const std::vector<double> px{0.5, 0.5};
  CHECK(infolerp::checked_mutual_information(px, std::vector<double>{1.0, 0.0, 1.0}).error().code() == infolerp::errc::bad_size);
  auto r = infolerp::checked_mutual_information(px, std::vector<double>{1.0, 0.0, 0.0, 0.0});
  CHECK(r.error().code() == infolerp::errc::bad_distribution);
  CHECK(r.error().element() == 1);
  CHECK(r.error().message().find("row 1") != std::string::npos);
  r = infolerp::checked_conditional_entropy(px, std::vector<double>{1.0, 0.0, 0.5, -0.5});
  CHECK(r.error().code() == infolerp::errc::bad_distribution);
  CHECK(r.error().element() == 3);
  r = infolerp::checked_conditional_entropy(std::vector<double>{1.0, std::numeric_limits<double>::infinity()},
                                            std::vector<double>{1.0, 0.0, 0.5, 0.5});
  CHECK(r.error().code() == infolerp::errc::non_finite);
  CHECK(r.error().element() == 1);
  // An all-zero row is fine when its input never occurs.
  CHECK(checked(infolerp::checked_mutual_information(std::vector<double>{1.0, 0.0}, std::vector<double>{0.3, 0.7, 0.0, 0.0})) == 0.0);
  // Unnormalised rows and inputs are normalised.
  CHECK(checked(infolerp::checked_mutual_information(std::vector<double>{2.0, 2.0}, std::vector<double>{5.0, 0.0, 0.0, 3.0})) ==
        Approx(1.0).margin(1e-15));
}

TEST_CASE("mutual_information_lower_bound: at most I(x;Y), equal to log2(e) times its scalar sum") {
  std::mt19937_64 rng(21);
  for (std::size_t n : {1u, 3u, 4u, 5u, 8u, 17u, 64u, 70u}) {
    for (int trial = 0; trial < 20; ++trial) {
      const auto r = random_distribution(n, rng, 0.4), q = random_distribution(n, rng, 0.2);
      const std::vector<float> row(r.begin(), r.end());
      double reference = 0.0;
      for (std::size_t i = 0; i < n; ++i)
        if (row[i] > 0.0f && q[i] > 0.0) reference += static_cast<double>(row[i]) - q[i];
      reference *= 1.4426950408889634;
      const double bound = infolerp::mutual_information_lower_bound(row, q);
      CHECK(bound == Approx(reference).margin(1e-15));
      CHECK(bound <= infolerp::element_mutual_information(row, q) + 1e-12);
    }
  }
}
