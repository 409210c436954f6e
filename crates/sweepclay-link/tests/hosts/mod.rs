//! Real print hosts on loopback for the tests: OctoPrint with its bundled
//! virtual printer, and Moonraker without Klipper. `scripts/test` installs
//! both from PyPI into virtual environments when they are missing and
//! names them in `SWEEPCLAY_OCTOPRINT` and `SWEEPCLAY_MOONRAKER` (the
//! programs). Without them the tests fail and say so;
//! `SWEEPCLAY_SKIP_HOSTS=1` skips them on purpose (never in CI).

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A server process, killed when dropped.
pub struct Server {
    child: Child,
    /// Its address, `http://127.0.0.1:PORT`.
    pub url: String,
    /// Its API key (OctoPrint's global key; Moonraker needs none).
    pub key: String,
    /// Its data folder.
    pub dir: PathBuf,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A port nothing listens on now.
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// The program named by `env`, or None when the hosts are skipped.
fn program(env: &str) -> Option<PathBuf> {
    if std::env::var("SWEEPCLAY_SKIP_HOSTS").is_ok_and(|v| v == "1") {
        eprintln!("SWEEPCLAY_SKIP_HOSTS=1: print host test skipped");
        return None;
    }
    let p = std::env::var_os(env).map(PathBuf::from).unwrap_or_else(|| {
        panic!(
            "the print host tests need OctoPrint and Moonraker from PyPI: run `scripts/test`, \
             which installs them, or set {env} to the program (SWEEPCLAY_SKIP_HOSTS=1 skips them)"
        )
    });
    assert!(p.exists(), "{env}={}: no such program", p.display());
    Some(p)
}

/// Waits until `ready` says yes, or panics after `secs` with the log.
fn wait(secs: u64, what: &str, log: &Path, mut ready: impl FnMut() -> bool) {
    let deadline = Instant::now() + Duration::from_secs(secs);
    while !ready() {
        if Instant::now() > deadline {
            let tail = std::fs::read_to_string(log).unwrap_or_default();
            let tail: String = tail.lines().rev().take(30).collect::<Vec<_>>().join("\n");
            panic!("{what} did not start within {secs} s; its log, last lines first:\n{tail}");
        }
        std::thread::sleep(Duration::from_millis(250));
    }
}

/// A blocking GET with headers: status and body, or None if nothing answers.
fn get(url: &str, key: &str) -> Option<(u16, String)> {
    use std::io::{Read, Write};
    let rest = url.strip_prefix("http://")?;
    let (host, path) = rest
        .split_once('/')
        .map_or((rest, "/".to_string()), |(h, p)| (h, format!("/{p}")));
    let mut s = std::net::TcpStream::connect(host).ok()?;
    s.set_read_timeout(Some(Duration::from_secs(5))).ok()?;
    write!(
        s,
        "GET {path} HTTP/1.0\r\nHost: {host}\r\nX-Api-Key: {key}\r\n\r\n"
    )
    .ok()?;
    let mut out = String::new();
    s.read_to_string(&mut out).ok()?;
    let status = out.split_whitespace().nth(1)?.parse().ok()?;
    let body = out
        .split_once("\r\n\r\n")
        .map_or("", |(_, b)| b)
        .to_string();
    Some((status, body))
}

/// OctoPrint on loopback with its virtual printer connected and a global
/// API key; `serial.log` records every line the printer received.
pub fn octoprint(dir: &Path) -> Option<Server> {
    let prog = program("SWEEPCLAY_OCTOPRINT")?;
    let port = free_port();
    let key = "SWEEPCLAYTESTKEY0123456789ABCDEF".to_string();
    std::fs::create_dir_all(dir).unwrap();
    // First-run wizards, online checks and plugins that call out are off;
    // the virtual printer answers at once (no throttle).
    std::fs::write(
        dir.join("config.yaml"),
        format!(
            "api:\n  key: {key}\nserver:\n  firstRun: false\n  onlineCheck:\n    enabled: false\n  \
             pluginBlacklist:\n    enabled: false\n  seenWizards:\n    corewizard: 4\n    backup: null\n\
             plugins:\n  tracking:\n    enabled: false\n  announcements:\n    enabled: false\n  \
             softwareupdate:\n    enabled: false\n\
             serial:\n  autoconnect: true\n  port: VIRTUAL\n  baudrate: 115200\n  log: true\n\
             devel:\n  virtualPrinter:\n    enabled: true\n    throttle: 0.0\n"
        ),
    )
    .unwrap();
    let log = dir.join("serve.log");
    let child = Command::new(&prog)
        .args(["serve", "--iknowwhatimdoing", "--basedir"])
        .arg(dir)
        .args(["--host", "127.0.0.1", "--port", &port.to_string()])
        .stdout(std::fs::File::create(&log).unwrap())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("starting {}: {e}", prog.display()));
    let server = Server {
        child,
        url: format!("http://127.0.0.1:{port}"),
        key,
        dir: dir.to_path_buf(),
    };
    wait(120, "OctoPrint with its virtual printer", &log, || {
        get(&format!("{}/api/connection", server.url), &server.key)
            .is_some_and(|(s, b)| s == 200 && b.contains("\"Operational\""))
    });
    Some(server)
}

/// Moonraker on loopback without Klipper: files can be uploaded and
/// listed; printing needs Klipper, which is not here.
pub fn moonraker(dir: &Path) -> Option<Server> {
    let prog = program("SWEEPCLAY_MOONRAKER")?;
    let port = free_port();
    for d in ["config", "gcodes", "logs"] {
        std::fs::create_dir_all(dir.join(d)).unwrap();
    }
    let conf = dir.join("config").join("moonraker.conf");
    std::fs::write(
        &conf,
        format!(
            "[server]\nhost: 127.0.0.1\nport: {port}\nklippy_uds_address: {}\n\n\
             [authorization]\nforce_logins: False\ntrusted_clients:\n  127.0.0.0/8\n\n\
             [file_manager]\nenable_object_processing: False\n",
            dir.join("klippy.sock").display()
        ),
    )
    .unwrap();
    let log = dir.join("logs").join("moonraker.log");
    let child = Command::new(&prog)
        .arg("-d")
        .arg(dir)
        .arg("-c")
        .arg(&conf)
        .arg("-l")
        .arg(&log)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("starting {}: {e}", prog.display()));
    let server = Server {
        child,
        url: format!("http://127.0.0.1:{port}"),
        key: String::new(),
        dir: dir.to_path_buf(),
    };
    wait(60, "Moonraker", &log, || {
        get(&format!("{}/server/info", server.url), "").is_some_and(|(s, _)| s == 200)
    });
    Some(server)
}

/// The commands OctoPrint's virtual printer received, in order, as
/// `serial.log` records them (`Send: N12 G1 X1*34` → `G1 X1`).
pub fn received(server: &Server) -> Vec<String> {
    let text =
        std::fs::read_to_string(server.dir.join("logs").join("serial.log")).unwrap_or_default();
    text.lines()
        .filter_map(|l| l.split_once(" - Send: ").map(|(_, c)| c))
        .map(|c| {
            let c = c.split('*').next().unwrap_or(c);
            let c = match c.strip_prefix('N') {
                Some(rest) => rest.split_once(' ').map_or("", |(_, cmd)| cmd),
                None => c,
            };
            c.trim().to_string()
        })
        .collect()
}

/// A G-code file's commands as a host sends them: comments and blank
/// lines dropped.
pub fn commands(gcode: &str) -> Vec<String> {
    gcode
        .lines()
        .map(|l| l.split(';').next().unwrap_or("").trim().to_string())
        .filter(|l| !l.is_empty())
        .collect()
}

/// Asserts that the printer received every command of `gcode`, in order,
/// among the host's own (temperature polls, line-number resets).
pub fn assert_received_in_order(server: &Server, gcode: &str) {
    let sent = received(server);
    let want = commands(gcode);
    let mut it = sent.iter();
    for (i, w) in want.iter().enumerate() {
        assert!(
            it.any(|s| s == w),
            "the printer never received command {} of {} (`{w}`) after the ones before it; it received {} lines",
            i + 1,
            want.len(),
            sent.len()
        );
    }
}
