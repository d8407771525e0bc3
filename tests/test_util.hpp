// tests/test_util.hpp: small helpers shared by the tests (not part of the library).
#pragma once
#include <petscsys.h>
#include <cstdint>
#include <cstring>
#include <vector>

namespace rbctest {

// FNV-style hash of the bits of a vector of reals: bit-for-bit comparisons across runs and ranks.
inline std::uint64_t Hash(std::uint64_t h, const std::vector<PetscReal> &v)
{
  for (PetscReal d : v) {
    std::uint64_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    h = (h ^ bits) * 0x100000001B3ULL;
  }
  return h;
}

} // namespace rbctest
