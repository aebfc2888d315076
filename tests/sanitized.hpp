// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// ASPERITY_SANITIZED: this test binary is built with AddressSanitizer or ThreadSanitizer (gcc or
// clang). Tests whose point is a rate or a power over many repetitions assert it in the Release
// pass and run a few repetitions under the sanitizers (each costs ~10-15x there): the sanitizers
// check memory and threads on the same code paths, the Release pass checks the statistics.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ASPERITY_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define ASPERITY_SANITIZED 1
#endif
#endif

namespace asperity::testing {
#ifdef ASPERITY_SANITIZED
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
}  // namespace asperity::testing
