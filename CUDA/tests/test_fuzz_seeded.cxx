// The fuzz properties of FuzzEntryPoints.h on seeded random inputs, in every CI run (the
// libFuzzer target explores further: `bash .ci/setup.sh fuzz`). A broken property aborts
// with its description; a death test keeps that from ending the test binary.
#include "fuzz/FuzzEntryPoints.h"

#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <vector>

namespace
{

TEST(FuzzSeeded, RandomInputsThroughEveryEntryPoint)
{
  // A fixed number of inputs from a fixed seed: the same inputs every run, so a failure
  // reproduces.
  constexpr int kInputs = 3000;
  std::mt19937_64 rng(20261201);
  const auto start = std::chrono::steady_clock::now();
  for (int input = 0; input < kInputs; ++input)
  {
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(16 + rng() % 3000));
    for (auto& b : bytes)
      b = static_cast<std::uint8_t>(rng());
    vaofuzz::fuzzOnce(bytes.data(), bytes.size());
  }
  std::cout << "[ fuzz     ] " << kInputs << " inputs in "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
            << " s\n";
}

TEST(FuzzSeeded, ABrokenPropertyIsReported)
{
  // The harness must be able to fail: a violated property aborts with its description.
  EXPECT_DEATH(
    vaofuzz::check(false, "a deliberately broken property"), "a deliberately broken property");
}

} // namespace
