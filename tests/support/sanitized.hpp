// SPDX-License-Identifier: Apache-2.0
// Test support: whether this build runs under AddressSanitizer, so that slow acceptance
// checks can run the same assertions on fewer frames there.
#pragma once

namespace hrcsense::test {

#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;  // GCC
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;  // clang
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

}  // namespace hrcsense::test
