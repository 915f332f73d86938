#include "posefilter/rng.h"

#include <cmath>

namespace posefilter {
namespace {

std::uint64_t SplitMix64(std::uint64_t* x) {
  std::uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

std::uint64_t Rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

}  // namespace

Rng::Rng(std::uint64_t seed) {
  std::uint64_t x = seed;
  for (auto& s : s_) s = SplitMix64(&x);
}

std::uint64_t Rng::NextU64() {  // xoshiro256**
  const std::uint64_t result = Rotl(s_[1] * 5, 7) * 9;
  const std::uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = Rotl(s_[3], 45);
  return result;
}

double Rng::Uniform() { return double(NextU64() >> 11) * 0x1.0p-53; }

std::uint64_t Rng::UniformInt(std::uint64_t n) {
  // Rejection sampling on the top of the range: unbiased.
  const std::uint64_t limit = ~0ull - (~0ull % n);
  std::uint64_t r;
  do r = NextU64(); while (r >= limit);
  return r % n;
}

double Rng::Normal() {
  // Box–Muller (eq. 5.1 [ALGORITHM.md]): Z1 = √(−2 ln U1)·sin(2πU2), Z2 = √(−2 ln U1)·cos(2πU2); U1 ∈ (0, 1].
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - Uniform();
  const double u2 = Uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::cos(2 * M_PI * u2);
  has_spare_ = true;
  return r * std::sin(2 * M_PI * u2);
}

Rng Rng::Split() { return Rng(NextU64() ^ 0xA0761D6478BD642Full); }

}  // namespace posefilter
