//! A fuzz test of the import endpoints' work (`api::import`, what
//! `POST /api/import/svg` and `/api/import/csv` run), from a fixed seed in
//! CI (`FUZZ_SEED`, `PROPTEST_CASES` for others): SVGs and CSVs built from
//! drawing fragments — nested groups, transforms with huge and tiny
//! scales, curves, arcs, shapes with odd attributes, entities, broken
//! numbers — and raw bytes. Every answer is a result or an error naming
//! its reason (never a panic), within a bounded time, and an accepted
//! import has at most the points its caps allow.

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
#[path = "../../sweepclay-plan/tests/seeds/mod.rs"]
mod seeds;
use sweepclay_web::api;

fn cases() -> u32 {
    seeds::cases(300)
}

fn seed() -> RngSeed {
    seeds::seed("FUZZ_SEED", 20261204)
}

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        (-1e3..1e3f64).prop_map(|v| format!("{v:.3}")),
        Just("1e308".to_string()),
        Just("-1e-308".to_string()),
        Just("NaN".to_string()),
        Just("inf".to_string()),
        Just("".to_string()),
        Just("1,5".to_string()),
        (0u32..1_000_000).prop_map(|v| v.to_string()),
    ]
}

fn fragment() -> impl Strategy<Value = String> {
    let n = number;
    prop_oneof![
        (n(), n(), n(), n()).prop_map(|(a, b, c, d)| format!(
            r#"<path d="M{a} {b} C {c} {d} {b} {a} {c} {c} L {d} {a} Z"/>"#
        )),
        (n(), n(), n())
            .prop_map(|(a, b, c)| format!(r#"<path d="M0 0 A {a} {b} {c} 1 1 {a} {b}"/>"#)),
        (n(), n(), n()).prop_map(|(a, b, c)| format!(r#"<circle cx="{a}" cy="{b}" r="{c}"/>"#)),
        (n(), n(), n(), n()).prop_map(|(a, b, c, d)| format!(
            r#"<rect x="{a}" y="{b}" width="{c}" height="{d}"/>"#
        )),
        (n(), n(), n(), n())
            .prop_map(|(a, b, c, d)| format!(r#"<polyline points="{a},{b} {c},{d} {a} {d}"/>"#)),
        (n(), n()).prop_map(|(a, b)| format!(r#"<ellipse rx="{a}" ry="{b}"/>"#)),
        (n(), 1usize..300)
            .prop_map(|(s, k)| format!(r#"{}<g transform="scale({s})">"#, "<g>".repeat(k))),
        Just("</g>".to_string()),
        Just("<defs>".to_string()),
        Just("</defs>".to_string()),
        Just("<!ENTITY x \"y\">".to_string()),
        Just("&x;".to_string()),
        "[ -~]{0,40}".prop_map(|s| s),
    ]
}

fn svg() -> impl Strategy<Value = String> {
    (number(), number(), prop::collection::vec(fragment(), 0..12)).prop_map(|(w, h, body)| {
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}mm" height="{h}mm" viewBox="0 0 100 100">{}</svg>"#,
            body.concat()
        )
    })
}

fn csv() -> impl Strategy<Value = String> {
    prop::collection::vec(
        (
            number(),
            number(),
            prop_oneof![Just(","), Just(";"), Just("\t"), Just(" ")],
        ),
        0..200,
    )
    .prop_map(|rows| {
        rows.into_iter()
            .map(|(x, y, sep)| format!("{x}{sep}{y}\n"))
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, rng_seed: seed(), .. ProptestConfig::default() })]

    #[test]
    fn imports_answer_every_file_within_their_caps(
        (format, text) in prop_oneof![
            svg().prop_map(|t| ("svg", t)),
            csv().prop_map(|t| ("csv", t)),
            prop::collection::vec(any::<u8>(), 0..2000).prop_map(|b| ("svg", String::from_utf8_lossy(&b).into_owned())),
        ]
    ) {
        let t0 = std::time::Instant::now();
        match api::import(format, &text) {
            Ok(v) => {
                let points: usize = v.shapes.iter().map(|s| s.path.points.len()).sum();
                prop_assert!(points <= sweepclay_core::import::MAX_SHAPES * sweepclay_core::import::MAX_POINTS * 4, "{points}");
            }
            Err(e) => prop_assert!(!e.error.is_empty()),
        }
        prop_assert!(t0.elapsed().as_secs_f64() < 5.0, "{format}: {:?}", t0.elapsed());
    }
}
