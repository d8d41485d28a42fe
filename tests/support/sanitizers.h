#pragma once
/// MC_UNDER_ASAN: 1 when the test is built with AddressSanitizer (GCC defines
/// __SANITIZE_ADDRESS__, clang answers __has_feature), for the few tests whose rates or timings
/// are properties of an optimised build and get a wider bound under the sanitizer presets.
#if defined(__SANITIZE_ADDRESS__)
#define MC_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MC_UNDER_ASAN 1
#endif
#endif
#ifndef MC_UNDER_ASAN
#define MC_UNDER_ASAN 0
#endif

/// MC_UNDER_TSAN: 1 when the test is built with ThreadSanitizer, whose runtime defines the global
/// operator new/delete itself (the allocation counter then counts through its malloc hook).
#if defined(__SANITIZE_THREAD__)
#define MC_UNDER_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define MC_UNDER_TSAN 1
#endif
#endif
#ifndef MC_UNDER_TSAN
#define MC_UNDER_TSAN 0
#endif

/// MC_UNDER_SANITIZER: 1 under either sanitizer. Both slow the code they instrument several times
/// (ThreadSanitizer more than AddressSanitizer on the camera's tracking), so a live test's
/// timeouts and the precision it can reach in them get the sanitizer presets' wider bounds.
#define MC_UNDER_SANITIZER (MC_UNDER_ASAN || MC_UNDER_TSAN)

namespace mc::test {
/// The slack a fault's detection gets beyond its timeout and one poll: a loaded machine's
/// scheduling (50 ms), and under a sanitizer a bus thread starved for several periods by the
/// instrumented loop beside it (measured: 184 ms for a 100 ms timeout under ThreadSanitizer).
inline constexpr double kFaultSlack_s = MC_UNDER_SANITIZER ? 0.2 : 0.05;
}  // namespace mc::test
