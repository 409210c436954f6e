//! `scripts/test`, the README's test command: where the browser test's
//! Chromium is missing and cannot be installed, it says so in one line and
//! fails, before running any test (never a silent skip).

use std::os::unix::fs::{symlink, PermissionsExt};
use std::path::{Path, PathBuf};
use std::process::Command;

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/test")
}

/// A directory for PATH holding only what the script needs before it
/// looks for Chromium: no chromium, no chromedriver, no apt-get.
fn bare_path(uid: Option<&str>) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for tool in ["dirname", "mktemp"] {
        let real = ["/usr/bin", "/bin"]
            .iter()
            .map(|d| Path::new(d).join(tool))
            .find(|p| p.exists())
            .unwrap();
        symlink(real, dir.path().join(tool)).unwrap();
    }
    let id = dir.path().join("id");
    match uid {
        // A user who is not root (and has no sudo here).
        Some(uid) => {
            std::fs::write(&id, format!("#!/bin/sh\necho {uid}\n")).unwrap();
            std::fs::set_permissions(&id, std::fs::Permissions::from_mode(0o755)).unwrap();
        }
        None => symlink("/usr/bin/id", &id).unwrap(),
    }
    dir
}

fn run(path: &Path) -> std::process::Output {
    Command::new("/bin/bash")
        .arg(script())
        .env_clear()
        .env("PATH", path)
        .env("HOME", "/tmp")
        .output()
        .unwrap()
}

fn one_line_failure(out: &std::process::Output, says: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains(says) && err.contains("SWEEPCLAY_SKIP_BROWSER=1"),
        "{err}"
    );
}

#[test]
fn without_chromium_and_without_a_way_to_install_it_the_script_fails_in_one_line() {
    // Not root and no sudo.
    let user = bare_path(Some("1000"));
    one_line_failure(&run(user.path()), "not root, no sudo");
    // Root, but no apt-get on the PATH.
    if String::from_utf8_lossy(&Command::new("id").arg("-u").output().unwrap().stdout).trim() == "0"
    {
        let root = bare_path(None);
        one_line_failure(&run(root.path()), "no apt-get");
    }
}
