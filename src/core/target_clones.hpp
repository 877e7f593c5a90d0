// The library's one way to build a loop for several instruction sets: the compiler's target
// clones. A function marked ROUGHSCOPE_TARGET_CLONES is compiled once per instruction set of the
// list and once for the baseline; the program's loader picks the best build the processor runs
// (an ifunc resolver, once), so a call costs what a call to a plain function does. Write the loop
// once, for the auto-vectoriser (plain arrays, restrict, no branches), in an always_inline body
// and call it from the cloned function. Two limits of the compilers: a function template cannot
// be cloned with clang 14 (clone a plain function that picks the template's instance), and GCC 12
// calls a cloned function as if it could not throw (an exception leaving it ends the program:
// catch inside and return it, std::exception_ptr, for the caller to throw).
//
// The list: x86-64-v4 (AVX-512 F, BW, CD, DQ, VL) and x86-64-v3 (AVX2, FMA, BMI2) with GCC;
// AVX-512F and AVX2 with clang (clang 14 makes no clone for an `arch=` entry). Elsewhere (not
// x86-64, not ELF) one build.
#pragma once

#if defined(__x86_64__) && defined(__ELF__) && defined(__clang__)
#define ROUGHSCOPE_TARGET_CLONES [[gnu::target_clones("avx512f", "avx2", "default")]]
#elif defined(__x86_64__) && defined(__ELF__) && defined(__GNUC__)
#define ROUGHSCOPE_TARGET_CLONES \
    [[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]]
#else
#define ROUGHSCOPE_TARGET_CLONES
#endif
