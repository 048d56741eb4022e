/* SPDX-License-Identifier: MIT */
/* Tangled from literate/quadric.org: do not edit; edit the .org and run make tangle. */
/* Private: how the library's lane kernels are compiled (quadric.c,
   discover.c).  Not installed. */
#ifndef FOLDEST_LANES_H
#define FOLDEST_LANES_H

/* No clones under ThreadSanitizer: the loader runs the clone's resolver
   before the sanitizer's runtime is up, and the instrumented resolver
   crashes. */
#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define FE__LANES_TSAN 1
#endif
#endif
#if defined(__SANITIZE_THREAD__)
#define FE__LANES_TSAN 1
#endif

#if defined(__GNUC__) && defined(__x86_64__) && defined(__ELF__) \
    && !defined(FE_NO_CLONES)
#define FE__LANES_X86 1
#endif

#if defined(__GNUC__)
#define FE__PREFETCH(p) __builtin_prefetch((p), 0, 3)
#else
#define FE__PREFETCH(p) ((void)(p))
#endif

/* Contract x * y + s into one fused multiply-add: GCC needs asking. */
#if defined(__GNUC__) && !defined(__clang__)
#define FE__LANES_CONTRACT optimize("fp-contract=fast"),
#define FE__LANES_WIDE_TARGET target("avx512f,fma,prefer-vector-width=512")
#else
#define FE__LANES_CONTRACT
#define FE__LANES_WIDE_TARGET target("avx512f,fma")
#endif

/* Before a four-lane kernel: fma and default clones where they exist. */
#if defined(FE__LANES_X86) && !defined(FE__LANES_TSAN)
#define FE__LANES_CLONES \
    __attribute__((FE__LANES_CONTRACT target_clones("fma", "default")))
#else
#define FE__LANES_CLONES
#endif

/* Before an eight-lane kernel, compiled only where FE__LANES_X86. */
#define FE__LANES_WIDE __attribute__((FE__LANES_CONTRACT FE__LANES_WIDE_TARGET))

/* True when the eight-lane variant may run. */
#if defined(FE__LANES_X86)
#define FE__LANES_HAVE_WIDE() __builtin_cpu_supports("avx512f")
#else
#define FE__LANES_HAVE_WIDE() 0
#endif

#endif /* FOLDEST_LANES_H */
