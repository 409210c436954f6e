//! The random tests' case counts and seeds: fixed in CI, set by the
//! environment for longer runs over other seeds.

use proptest::test_runner::RngSeed;

/// `PROPTEST_CASES`, else `default`.
pub fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// The seed in the environment variable `var`, else `default`.
pub fn seed(var: &str, default: u64) -> RngSeed {
    RngSeed::Fixed(
        std::env::var(var)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(default),
    )
}
