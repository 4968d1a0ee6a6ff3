#pragma once
// Stream compaction of the particle loops: the overlap tests write a byte per candidate (a loop
// that vectorises), and these append the flagged candidates, in order, to index lists. The
// scalar form (store, then advance the count by the flag) has a dependence through the count and
// costs a cycle or two per candidate, which on the full contact list of a step is a fifth of the
// contact search; with AVX-512 (VL, BW) eight candidates go per compress instruction. Both forms
// write the same values in the same order.
#include <cstddef>
#include <cstdint>

#if defined(__AVX512F__) && defined(__AVX512VL__) && defined(__AVX512BW__)
#include <immintrin.h>
#define BOYCOTT_FLAG_COMPRESS_AVX512 1
#endif

namespace boycott::particles {

/// For each p in [0, n) with flag[p] != 0, in order: out_p[k] = p and, with `a`, out_a[k] = a[p].
/// Returns the number k of flagged p. out_p and out_a must have room for n values: the vector
/// form stores whole groups of 8 beyond k (never beyond n).
inline std::size_t compress_flagged(std::size_t n, const std::uint8_t* __restrict flag,
                                    const std::uint32_t* __restrict a, std::uint32_t* __restrict out_a,
                                    std::uint32_t* __restrict out_p) {
  std::size_t k = 0, p = 0;
#if defined(BOYCOTT_FLAG_COMPRESS_AVX512)
  // 256-bit vectors: the particle files prefer them (solver/particles/CMakeLists.txt).
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (; p + 8 <= n; p += 8) {
    const __m128i f = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(flag + p));
    const __mmask8 m = static_cast<__mmask8>(_mm_test_epi8_mask(f, f));
    const __m256i idx = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(p)), lane);
    // compress into a register, then a full store: the memory form of the compress is slow on
    // some cores; the lanes past the count are overwritten by the next group
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out_p + k), _mm256_maskz_compress_epi32(m, idx));
    if (a) {
      const __m256i av = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + p));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out_a + k), _mm256_maskz_compress_epi32(m, av));
    }
    k += static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(m)));
  }
#endif
  if (a) {
    for (; p < n; ++p) {
      out_a[k] = a[p];
      out_p[k] = static_cast<std::uint32_t>(p);
      k += flag[p] != 0;
    }
  } else {
    for (; p < n; ++p) {
      out_p[k] = static_cast<std::uint32_t>(p);
      k += flag[p] != 0;
    }
  }
  return k;
}

}  // namespace boycott::particles
