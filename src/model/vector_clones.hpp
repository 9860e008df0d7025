// SPDX-License-Identifier: GPL-3.0-or-later
// FIBERFLUID_VECTOR_CLONES before a loop function compiles it three times,
// for x86-64-v4 (AVX-512), x86-64-v3 (AVX2 and FMA) and the portable
// baseline, and the loader picks the widest the CPU has (GCC's
// target_clones, an ifunc): the default build stays portable. Empty with
// clang (the fuzz build) and under AddressSanitizer (whose runtime starts
// after the loader runs ifunc resolvers): the baseline alone.
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && \
    !defined(__SANITIZE_ADDRESS__)
#define FIBERFLUID_VECTOR_CLONES \
  __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define FIBERFLUID_VECTOR_CLONES
#endif
