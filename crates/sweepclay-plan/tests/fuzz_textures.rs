//! A fuzz test of a design's `texture` entries as a hostile file or page
//! writes them, from a fixed seed in CI (`FUZZ_SEED`, `PROPTEST_CASES` for
//! others): kinds known and unknown, keys of another kind, numbers out of
//! range, NaN-like strings, pictures whose bytes are flipped, truncated,
//! random, or whose header claims a huge size. Reading the design and
//! slicing it, through the plan as `slice` and the server run it, either
//! prints, or is refused by an error naming its `texture…` key (or the
//! design's shape): never a panic, within the caps on entries and pixels
//! (docs/FORMATS.md, docs/CHECKER.md "Bounded cost").

use base64::Engine as _;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
mod seeds;
use sweepclay_core::Design;
use sweepclay_plan::{slice_checked, Cancel, Unchecked};

fn cases() -> u32 {
    seeds::cases(120)
}

fn seed() -> RngSeed {
    seeds::seed("FUZZ_SEED", 20261204)
}

/// A valid greyscale PNG, `w` × `h`, of stripes.
fn png(w: u32, h: u32) -> Vec<u8> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, w, h);
        enc.set_color(png::ColorType::Grayscale);
        let mut wr = enc.write_header().unwrap();
        let data: Vec<u8> = (0..w * h)
            .map(|i| {
                if ((i % w) / 3).is_multiple_of(2) {
                    255
                } else {
                    0
                }
            })
            .collect();
        wr.write_image_data(&data).unwrap();
    }
    bytes
}

/// A picture as a hostile file carries it: valid, bytes flipped, cut
/// short, its header's size raised (CRC left wrong or made right), or
/// random bytes.
fn picture() -> impl Strategy<Value = String> {
    let b64 = |v: Vec<u8>| base64::engine::general_purpose::STANDARD.encode(v);
    prop_oneof![
        (1u32..40, 1u32..40).prop_map(move |(w, h)| b64(png(w, h))),
        (
            (4u32..30, 4u32..30),
            prop::collection::vec((0usize..400, any::<u8>()), 1..6)
        )
            .prop_map(move |((w, h), flips)| {
                let mut v = png(w, h);
                let n = v.len();
                for (at, b) in flips {
                    v[at % n] ^= b | 1;
                }
                b64(v)
            }),
        ((4u32..30, 4u32..30), 0usize..200).prop_map(move |((w, h), keep)| {
            let mut v = png(w, h);
            v.truncate(keep.min(v.len()));
            b64(v)
        }),
        ((1u32..=u32::MAX, 1u32..=u32::MAX), any::<bool>()).prop_map(move |((w, h), crc)| {
            // IHDR's width and height are bytes 16..24; its CRC 29..33.
            let mut v = png(8, 8);
            v[16..20].copy_from_slice(&w.to_be_bytes());
            v[20..24].copy_from_slice(&h.to_be_bytes());
            if crc {
                let sum = crc32(&v[12..29]);
                v[29..33].copy_from_slice(&sum.to_be_bytes());
            }
            b64(v)
        }),
        prop::collection::vec(any::<u8>(), 0..300).prop_map(b64),
        Just("not base64 at all!".to_string()),
        Just(String::new()),
    ]
}

/// The CRC-32 PNG chunks carry (ISO 3309), for a header made to look right.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xFFFF_FFFFu32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 == 1 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

fn number() -> impl Strategy<Value = serde_json::Value> {
    prop_oneof![
        4 => (-5.0..5.0f64).prop_map(|v| serde_json::json!(v)),
        1 => (0.5..40.0f64).prop_map(|v| serde_json::json!(v)),
        1 => Just(serde_json::json!(1e308)),
        1 => Just(serde_json::json!(-1e308)),
        1 => Just(serde_json::json!(0)),
        1 => Just(serde_json::json!("NaN")),
        1 => Just(serde_json::json!(null)),
        1 => (0u64..5_000_000).prop_map(|v| serde_json::json!(v)),
    ]
}

/// A number a well-typed entry may carry: mostly in range, sometimes
/// zero, huge or tiny.
fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => -3.0..3.0f64,
        6 => 4.0..30.0f64,
        1 => Just(0.0),
        1 => Just(1e9),
        1 => Just(-1e9),
        1 => Just(1e-9),
    ]
}

/// A well-typed entry: a known kind with its own keys (values in range or
/// not), an image with any picture.
fn well_typed() -> impl Strategy<Value = serde_json::Value> {
    (0u8..4, value(), value(), value(), (value(), value()), picture()).prop_map(
        |(kind, amp, a, b, (fin, fout), pic)| {
            let mut t = match kind {
                0 => serde_json::json!({ "kind": "ripple", "period": a }),
                1 => serde_json::json!({ "kind": "flute", "count": a.abs().round().min(1e6) }),
                2 => serde_json::json!({ "kind": "spiral", "count": a.abs().round().min(1e6), "deg_per_mm": b }),
                _ => serde_json::json!({ "kind": "image", "png_base64": pic }),
            };
            t["amplitude"] = amp.into();
            if fin > 0.0 {
                t["fade_in"] = fin.into();
            }
            if fout > 0.0 {
                t["fade_out"] = fout.into();
            }
            t
        },
    )
}

/// A hostile entry: a kind (known or not) and a handful of keys, each of
/// any kind's or none, of any type.
fn hostile() -> impl Strategy<Value = serde_json::Value> {
    let kind = prop_oneof![
        Just("ripple"),
        Just("flute"),
        Just("spiral"),
        Just("image"),
        Just("knurl"),
        Just("")
    ];
    let key = prop_oneof![
        Just("amplitude"),
        Just("period"),
        Just("count"),
        Just("deg_per_mm"),
        Just("fade_in"),
        Just("fade_out"),
        Just("path"),
        Just("colour"),
    ];
    (
        kind,
        prop::collection::vec((key, number()), 0..5),
        prop::option::of(picture()),
    )
        .prop_map(|(kind, keys, pic)| {
            let mut t = serde_json::json!({ "kind": kind, "amplitude": 1.0 });
            for (k, v) in keys {
                t[k] = v;
            }
            if let Some(p) = pic {
                t["png_base64"] = p.into();
            }
            t
        })
}

fn entry() -> impl Strategy<Value = serde_json::Value> {
    prop_oneof![4 => well_typed(), 1 => hostile()]
}

/// A small cup for every case, so a case costs milliseconds.
fn cup(texture: Vec<serde_json::Value>) -> String {
    let mut d: serde_json::Value =
        serde_json::from_str(sweepclay_core::examples::example("cup").unwrap()).unwrap();
    d["texture"] = texture.into();
    d.to_string()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, rng_seed: seed(), .. ProptestConfig::default() })]

    #[test]
    fn hostile_textures_print_or_are_refused_by_name(
        entries in prop_oneof![
            8 => prop::collection::vec(entry(), 1..4),
            1 => prop::collection::vec(entry(), 17..40),
        ],
    ) {
        let n = entries.len();
        let text = cup(entries);
        let t0 = std::time::Instant::now();
        let d = match Design::from_json(&text) {
            Ok(d) => d,
            Err(e) => {
                let m = e.to_string();
                prop_assert!(m.contains("texture"), "refused without naming the texture: {m}");
                return Ok(());
            }
        };
        prop_assert!(n <= 16, "{n} entries accepted");
        match slice_checked(&d, 0.5, &Cancel::new(), || Ok(std::io::sink())) {
            Ok(c) => prop_assert!(
                c.report.printable,
                "fails its own check: {:?}\n{text}",
                c.report.failures
            ),
            Err(Unchecked::Design(e)) => {
                let m = e.to_string();
                prop_assert!(
                    m.contains("texture") || m.contains("too steeply") || m.contains("varies"),
                    "refused without naming why: {m}"
                );
            }
            Err(Unchecked::Io(e)) => prop_assert!(false, "{e}"),
        }
        // Bounded: a case is a small cup, whatever its pictures claim.
        prop_assert!(t0.elapsed().as_secs() < 30, "took {:?}", t0.elapsed());
    }
}
