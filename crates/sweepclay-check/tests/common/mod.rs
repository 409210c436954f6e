//! What the checker's integration tests share.

use sweepclay_check::Report;

/// The report fails for `what` and for nothing outside `allowed` (a pause
/// or a travel move also splits the extrusion run, for instance).
pub fn fails_for(r: &Report, what: &str, allowed: &[&str]) {
    assert!(
        !r.printable,
        "expected a failure for {what}:\n{}",
        r.render()
    );
    assert!(
        r.failures.iter().any(|f| f.contains(what)),
        "expected `{what}`:\n{}",
        r.render()
    );
    for f in &r.failures {
        assert!(
            f.contains(what) || allowed.iter().any(|a| f.contains(a)),
            "unexpected failure `{f}` for a `{what}` fixture:\n{}",
            r.render()
        );
    }
}
