//! Textures the clay cannot hold (docs/ALGORITHMS.md §11): reduced and
//! said so, or refused by name. Random textures on random walls and
//! vessels, through the correction loop with the checker as the oracle,
//! are sweepclay-web's tests/textures.rs.

mod common;

use sweepclay_core::{slice, Design};

fn profile(h: f64, lean: f64) -> serde_json::Value {
    serde_json::json!({ "control_points": [[0.0, 0.0], [lean, h / 2.0], [0.0, h]] })
}

/// A texture the clay cannot hold anywhere (ribs 40 mm deep every 4 mm)
/// is refused by name, as is one too fine to sample; a steep one is kept
/// where it can be and its reductions said.
#[test]
fn impossible_textures_are_reduced_or_refused_by_name() {
    let v = |tex: serde_json::Value| {
        Design::from_json(
            &serde_json::json!({
                "sweepclay": 1,
                "profile_start": profile(40.0, 0.0),
                "trajectory": { "control_points": [[-40.0, 20.0], [0.0, 50.0], [40.0, 20.0]] },
                "texture": [tex],
            })
            .to_string(),
        )
        .unwrap()
    };
    let fine = v(serde_json::json!({ "kind": "ripple", "amplitude": 1, "period": 2 }));
    let e = slice(&fine).unwrap_err().to_string();
    assert!(e.contains("texture[0]") && e.contains("period"), "{e}");
    // Ribs 40 mm deep every 4 mm: no layer can hold a step of them.
    let deep = v(serde_json::json!({ "kind": "ripple", "amplitude": 40, "period": 4 }));
    let e = slice(&deep).unwrap_err().to_string();
    assert!(
        e.contains("texture: ripple 40 mm cannot be kept anywhere"),
        "{e}"
    );
    // 4 mm deep every 8 mm: kept where the wall allows, reduced elsewhere
    // and said so.
    let steep = v(serde_json::json!({ "kind": "ripple", "amplitude": 4, "period": 8 }));
    let s = slice(&steep).unwrap();
    let said = s.corrected.report.summary().join("\n");
    assert!(said.contains("texture ripple 4 mm reduced on"), "{said}");
    let shares: f64 = s.corrected.report.texture.iter().map(|f| f.share).sum();
    assert!(shares > 0.0 && shares <= 1.0 + 1e-9, "{said}");
    assert!(common::check_fast(&s).printable);
}
