//! From the design to the machine over the real binary: `slice`, then
//! `send` to a real OctoPrint on loopback whose virtual printer prints the
//! pot line by line; `calibrate` from print to saved profile.

#[path = "../../sweepclay-link/tests/hosts/mod.rs"]
mod hosts;

use assert_cmd::Command;
use predicates::prelude::*;
use std::path::Path;

fn sweepclay(dir: &Path) -> Command {
    let mut c = Command::cargo_bin("sweepclay").unwrap();
    c.current_dir(dir)
        .env("SWEEPCLAY_CONFIG_DIR", dir.join("config"))
        .env_remove("SWEEPCLAY_HOST_KEY");
    c
}

/// A small cup, 20 mm tall with a floor: about 10,000 lines.
fn tiny_pot(dir: &Path) {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/cup.json"),
    )
    .unwrap();
    let mut d: serde_json::Value = serde_json::from_str(&text).unwrap();
    for k in ["profile_start", "profile_end"] {
        d[k]["control_points"] = serde_json::json!([[0, 0], [0.5, 8], [2, 20]]);
    }
    d["name"] = "tiny pot".into();
    std::fs::write(dir.join("pot.json"), d.to_string()).unwrap();
}

#[test]
fn a_pot_is_sliced_checked_sent_and_printed_line_for_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let Some(server) = hosts::octoprint(&d.join("octoprint")) else {
        return;
    };
    tiny_pot(d);
    // The studio's printer: a CERAMBOT Mini behind OctoPrint.
    std::fs::write(
        d.join("printer.json"),
        serde_json::json!({
            "name": "studio mini", "build_volume": [120, 135, 100], "origin": [60, 67.5],
            "host": {"kind": "octoprint", "url": server.url}
        })
        .to_string(),
    )
    .unwrap();
    sweepclay(d)
        .args([
            "slice",
            "pot.json",
            "--printer",
            "printer.json",
            "-o",
            "pot.gcode",
        ])
        .assert()
        .success();

    // No key yet: OctoPrint refuses, in one sentence, and nothing prints.
    sweepclay(d)
        .args(["send", "pot.gcode", "--printer", "printer.json"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("refused the API key"));
    // The key is saved from standard input, outside the profile.
    sweepclay(d)
        .args([
            "send",
            "pot.gcode",
            "--printer",
            "printer.json",
            "--save-key",
            "--watch",
        ])
        .write_stdin(format!("{}\n", server.key))
        .timeout(std::time::Duration::from_secs(300))
        .assert()
        .success()
        .stdout(predicate::str::contains("sent       pot.gcode"))
        .stdout(predicate::str::contains("started    pot.gcode"))
        .stdout(predicate::str::contains("printing   pot.gcode"))
        .stdout(predicate::str::contains(
            "ended      Operational, 100 % of the file",
        ));
    let profile = std::fs::read_to_string(d.join("printer.json")).unwrap();
    assert!(
        !profile.contains(&server.key),
        "the key went into the profile"
    );
    let keys = std::fs::read_to_string(d.join("config/host-keys.json")).unwrap();
    assert!(keys.contains(&server.key));
    // The virtual printer received every command of the file, in order.
    let gcode = std::fs::read_to_string(d.join("pot.gcode")).unwrap();
    hosts::assert_received_in_order(&server, &gcode);

    // A file that fails the check is not sent without --force: the pot
    // with a travel move in the middle of its wall.
    let lines: Vec<&str> = gcode.lines().collect();
    let mid = lines.len() / 2;
    let broken = format!(
        "{}\nG0 X5 Y5\n{}\n",
        lines[..mid].join("\n"),
        lines[mid..].join("\n")
    );
    std::fs::write(d.join("broken.gcode"), broken).unwrap();
    sweepclay(d)
        .args(["send", "broken.gcode", "--printer", "printer.json"])
        .assert()
        .code(1)
        .stderr(predicate::str::contains("not sent: the file does not pass"));
    sweepclay(d)
        .args([
            "send",
            "broken.gcode",
            "--printer",
            "printer.json",
            "--force",
        ])
        .assert()
        .success()
        .stderr(predicate::str::contains(
            "WARNING: sending a file that does NOT pass",
        ))
        .stdout(predicate::str::contains("sent       broken.gcode"));

    // A profile without a host, and an address with a password in it, are
    // each one plain message.
    sweepclay(d)
        .args(["send", "pot.gcode", "--printer", "cerambot-mini"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("names no print host"));
    sweepclay(d)
        .args([
            "send",
            "pot.gcode",
            "--host",
            "http://pi:raspberry@octopi.local",
            "--kind",
            "octoprint",
        ])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("user name or password"));
}

#[test]
fn calibrate_prints_a_checked_cylinder_and_finds_the_factor_back() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("printer.json"),
        r#"{"name": "studio", "e_per_mm3": 0.13, "start_gcode": "G28\n"}"#,
    )
    .unwrap();
    sweepclay(d)
        .args(["calibrate", "--printer", "printer.json", "-o", "cal.gcode"])
        .assert()
        .success()
        .stdout(predicate::str::contains("band 4"));
    // The print passes the independent check as written.
    sweepclay(d).args(["check", "cal.gcode"]).assert().code(0);
    // The extruder really lays 1.1 mm³ for every mm³ written: walls 10 %
    // thick, as a calliper reads them (to 0.05 mm).
    let truth = 0.13 / 1.1;
    let measured: Vec<String> = [3.0f64, 4.0, 5.0, 6.0]
        .iter()
        .zip([0.04, -0.05, 0.05, -0.03])
        .map(|(w, n)| format!("{:.2}", w * 0.13 / truth + n))
        .collect();
    let compute = || {
        sweepclay(d)
            .args([
                "calibrate",
                "--printer",
                "printer.json",
                "--print",
                "cal.gcode",
                "--measured",
                &measured.join(","),
            ])
            .assert()
            .success()
            .stdout(predicate::str::contains("saved      printer.json"))
            .stdout(predicate::str::contains("written with E per mm³ 0.13"));
        let saved: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("printer.json")).unwrap())
                .unwrap();
        (saved["e_per_mm3"].as_f64().unwrap(), saved)
    };
    let (e, saved) = compute();
    assert!((e - truth).abs() / truth < 0.02, "{e} vs {truth}");
    // The same walls again give the same E: the fit takes the E the print
    // was written with, not the profile's new one (before: 0.118 → 0.107
    // → 0.098, compounding).
    let (again, _) = compute();
    assert_eq!(again, e);
    // The rest of the profile is kept as written.
    assert_eq!(saved["start_gcode"], "G28\n");
    // Walls that disagree save nothing.
    sweepclay(d)
        .args([
            "calibrate",
            "--printer",
            "printer.json",
            "--measured",
            "3,5.5,4,6",
        ])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("nothing saved"));
}
