#pragma once
// Shared by tests/analysis/*_test.cpp: sensor constants, exception checks and
// point generators. Header-only; every generator is deterministic.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "analysis/core/cloud.hpp"
#include "analysis/core/errors.hpp"
#include "analysis/core/units.hpp"

namespace sailshape {

inline constexpr double kSigma = 0.004;  // sensor random error σ, SPEC §3

// A seed drawn fresh each run and printed; SAILSHAPE_TEST_SEED replays one.
inline uint64_t freshTestSeed() {
  const char* fixed = std::getenv("SAILSHAPE_TEST_SEED");
  const uint64_t seed = fixed ? std::strtoull(fixed, nullptr, 10) : std::random_device{}();
  std::printf("seed %llu (SAILSHAPE_TEST_SEED replays it)\n", static_cast<unsigned long long>(seed));
  return seed;
}

// Runs `f`, which must throw E whose message contains every part.
template <class E, class F>
void expectThrowWith(F f, const std::vector<std::string>& parts) {
  EXPECT_THROW(
      {
        try {
          f();
        } catch (const E& e) {
          const std::string what = e.what();
          for (const auto& part : parts) EXPECT_NE(what.find(part), std::string::npos) << what;
          throw;
        }
      },
      E);
}

// Runs `f`, which must throw InvalidInput whose message contains every part.
template <class F>
void expectInvalidInput(F f, const std::vector<std::string>& parts) {
  expectThrowWith<InvalidInput>(f, parts);
}

// Runs `f`, which must throw FileError whose message starts with `prefix` and contains every part.
inline void expectFileError(const std::function<void()>& f, const std::string& prefix,
                            const std::vector<std::string>& parts) {
  EXPECT_THROW(
      {
        try {
          f();
        } catch (const FileError& e) {
          const std::string what = e.what();
          EXPECT_EQ(what.rfind(prefix, 0), 0u) << "'" << what << "' does not start with '" << prefix << "'";
          for (const auto& part : parts)
            EXPECT_NE(what.find(part), std::string::npos) << "'" << what << "' lacks '" << part << "'";
          throw;
        }
      },
      FileError);
}

// The cloud without the points within `radius` of `corner`, and the nearest of
// those apart: a corner whose last sample stands alone.
struct LoneTip {
  Cloud rest;
  Vec3 tip = Vec3::Zero();
  double tip_distance_m = std::numeric_limits<double>::infinity();
};
inline LoneTip isolateTip(const Cloud& cloud, const Vec3& corner, double radius) {
  LoneTip out;
  for (const Vec3& p : cloud.points) {
    const double d = (p - corner).norm();
    if (d >= radius)
      out.rest.points.push_back(p);
    else if (d < out.tip_distance_m) {
      out.tip_distance_m = d;
      out.tip = p;
    }
  }
  return out;
}

// Point i of n nearly uniform on the unit sphere (Fibonacci lattice): no clumps,
// no edges, so every k-neighbourhood is close to a continuous spherical cap.
inline Vec3 fibonacciDirection(size_t i, size_t n) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(n);
  const double rho = std::sqrt(1.0 - z * z), phi = golden * static_cast<double>(i);
  return Vec3(rho * std::cos(phi), rho * std::sin(phi), z);
}

}  // namespace sailshape
