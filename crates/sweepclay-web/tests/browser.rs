//! End to end in a real headless Chromium (Debian's `chromium` and
//! `chromium-driver`), driven over WebDriver: load the page, drag a control
//! point, see the statistics change, undo, reload (autosave), download the
//! G-code and run the checker on it.
//!
//! The browser is required: without it the test fails and says how to
//! install it. `SWEEPCLAY_SKIP_BROWSER=1` skips it on purpose (never set in
//! CI). `SWEEPCLAY_SCREENSHOT=FILE.png` saves a screenshot of the page
//! (`SWEEPCLAY_VESSEL_SCREENSHOT` one of the vessel it imports);
//! `SWEEPCLAY_URL=http://127.0.0.1:PORT` tests a running `sweepclay serve`
//! instead of an in-process server.

use fantoccini::actions::{
    InputSource, MouseActions, PointerAction, TouchActions, MOUSE_BUTTON_LEFT,
};
use fantoccini::{Client, ClientBuilder};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

#[path = "../../sweepclay-link/tests/hosts/mod.rs"]
mod hosts;

struct Driver(Child);

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn find(env: &str, candidates: &[&str]) -> Option<PathBuf> {
    if let Ok(p) = std::env::var(env) {
        return Some(PathBuf::from(p));
    }
    candidates.iter().map(PathBuf::from).find(|p| p.exists())
}

async fn start_browser(download_dir: &Path, profile: &Path) -> Option<(Driver, Client)> {
    if std::env::var("SWEEPCLAY_SKIP_BROWSER").is_ok_and(|v| v == "1") {
        eprintln!("SWEEPCLAY_SKIP_BROWSER=1: browser test skipped");
        return None;
    }
    let missing = "the browser test needs Chromium and ChromeDriver: \
                   `apt-get install chromium chromium-driver` (or set CHROMIUM and CHROMEDRIVER; \
                   SWEEPCLAY_SKIP_BROWSER=1 skips this test)";
    let driver = find("CHROMEDRIVER", &["/usr/bin/chromedriver"]).expect(missing);
    let chromium = find(
        "CHROMIUM",
        &["/usr/bin/chromium", "/usr/bin/chromium-browser"],
    )
    .expect(missing);
    let port = hosts::free_port();
    let child = Command::new(&driver)
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("starting {}: {e}; {missing}", driver.display()));
    let guard = Driver(child);
    let mut args: Vec<String> = [
        "--headless=new",
        "--no-sandbox",
        "--disable-dev-shm-usage",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--window-size=1440,900",
    ]
    .map(String::from)
    .to_vec();
    args.push(format!("--user-data-dir={}", profile.display()));
    if let Ok(extra) = std::env::var("SWEEPCLAY_BROWSER_ARGS") {
        args.extend(extra.split_whitespace().map(String::from));
    }
    let caps = json!({
        "goog:chromeOptions": {
            "binary": chromium,
            "args": args,
            "prefs": {
                "download.default_directory": download_dir,
                "download.prompt_for_download": false,
            }
        }
    });
    let caps: serde_json::Map<String, Value> = serde_json::from_value(caps).unwrap();
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let connector = hyper_util::client::legacy::connect::HttpConnector::new();
        match ClientBuilder::new(connector)
            .capabilities(caps.clone())
            .connect(&format!("http://127.0.0.1:{port}"))
            .await
        {
            Ok(c) => return Some((guard, c)),
            Err(e) if Instant::now() > deadline => panic!("ChromeDriver did not start: {e}"),
            Err(_) => tokio::time::sleep(Duration::from_millis(200)).await,
        }
    }
}

async fn js(c: &Client, script: &str) -> Value {
    c.execute(script, vec![]).await.unwrap()
}

/// Polls a script until it returns something other than null/false.
/// Sets a form control's value and fires its `change`, as a user's entry
/// does.
async fn set_value(c: &Client, id: &str, value: &str) {
    c.execute(
        "const e = document.getElementById(arguments[0]); e.value = arguments[1]; e.dispatchEvent(new Event('change'));",
        vec![json!(id), json!(value)],
    )
    .await
    .unwrap();
}

/// Ticks a checkbox and fires its `change`, as a click does.
async fn set_checked(c: &Client, id: &str) {
    c.execute(
        "const e = document.getElementById(arguments[0]); e.checked = true; e.dispatchEvent(new Event('change'));",
        vec![json!(id)],
    )
    .await
    .unwrap();
}

async fn wait_js(c: &Client, script: &str, what: &str) -> Value {
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let v = js(c, script).await;
        if !(v.is_null() || v == Value::Bool(false)) {
            return v;
        }
        if Instant::now() > deadline {
            let errors = js(c, "return window.sweepclayErrors").await;
            let status = js(c, "return document.getElementById('status').textContent").await;
            panic!("timed out waiting for {what}; page errors {errors}, status {status}");
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

const SAMPLES: &str = "const e = document.querySelector('[data-stat=\"sample points\"]'); return e ? e.textContent : null";

/// Screen position (viewport px) of control point `i` of editor `e`.
async fn point_at(c: &Client, e: usize, i: &str) -> (f64, f64) {
    let v = js(
        c,
        &format!(
            "const ed = window.sweepclay.editors[{e}]; const i = {i};
             const p = ed.toScreen(ed.points[i]); const r = ed.canvas.getBoundingClientRect();
             return [r.left + p[0], r.top + p[1]];"
        ),
    )
    .await;
    (v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
}

/// Clicks "Download G-code" and waits (30 s at most, else fails with
/// `missing`) for a `.gcode` file in `downloads`.
async fn download_gcode(c: &Client, downloads: &Path, missing: &str) -> std::path::PathBuf {
    click(c, "download-gcode").await;
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let done = std::fs::read_dir(downloads)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.extension().is_some_and(|x| x == "gcode"));
        if let Some(p) = done {
            return p;
        }
        assert!(Instant::now() < deadline, "{missing}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

/// Downloads the page's G-code (`missing` says what failed if none
/// comes) and asserts the checker passes it for the design's printer
/// preset; its text and that printer.
async fn download_printable(
    c: &Client,
    downloads: &Path,
    missing: &str,
) -> (String, sweepclay_core::Printer) {
    let file = download_gcode(c, downloads, missing).await;
    let text = std::fs::read_to_string(&file).unwrap();
    let printer = js(c, "return window.sweepclay.design.printer").await;
    let printer = sweepclay_core::Printer::preset(printer.as_str().unwrap()).unwrap();
    let report = sweepclay_check::check(&text, &sweepclay_plan::printer_check(&printer));
    assert!(report.printable, "{:?}", report.failures);
    (text, printer)
}

/// Clicks the element with id `id`, waiting up to 15 s for it to take
/// clicks (a panel or dialog the page is still laying out is "not
/// interactable" for a moment; with the whole suite on 2 cores, once for
/// more than 5 s).
async fn click(c: &Client, id: &str) {
    let deadline = Instant::now() + Duration::from_secs(15);
    loop {
        let el = c.find(fantoccini::Locator::Id(id)).await.unwrap();
        // In view first: the printer dialog scrolls, and its buttons end
        // it (under load, WebDriver's own scrolling once left one outside).
        let _ = c
            .execute(
                "document.getElementById(arguments[0])?.scrollIntoView({block: 'center'})",
                vec![json!(id)],
            )
            .await;
        match el.click().await {
            Ok(_) => return,
            Err(fantoccini::error::CmdError::Standard(e))
                if e.error == fantoccini::error::ErrorStatus::ElementNotInteractable
                    && Instant::now() < deadline =>
            {
                tokio::time::sleep(Duration::from_millis(100)).await;
            }
            Err(e) => panic!("clicking #{id}: {e}"),
        }
    }
}

/// Waits for the error above the 3D view and returns its text.
async fn error_text(c: &Client, what: &str) -> Value {
    // Once the newest design has its answer: an older error may still
    // show while it is being sliced.
    wait_js(
        c,
        "return !window.sweepclay.inFlight && !window.sweepclay.pending && document.querySelector('#status .error')?.textContent || null",
        what,
    )
    .await
}

/// Clicks "Edit printer…" and waits for its dialog.
async fn open_printer_dialog(c: &Client) {
    click(c, "printer-edit").await;
    wait_js(
        c,
        "return document.getElementById('printer-dialog').open",
        "the printer dialog",
    )
    .await;
}

/// Ends a browser test: the page logged no error, and the browser closes.
async fn no_page_errors_and_close(c: Client) {
    assert_eq!(js(&c, "return window.sweepclayErrors").await, json!([]));
    c.close().await.unwrap();
}

/// Whether the verdict says printable.
const PRINTABLE: &str = "return document.getElementById('verdict').dataset.printable === 'true'";

/// Opens the page on t1 (the paper's first wall, which these tests were
/// written on), closes the first-run guide and waits for it to print.
async fn open_first_slice(c: &Client, base: &str) {
    c.goto(&format!("{base}/?example=t1")).await.unwrap();
    close_guide(c).await;
    wait_js(
        c,
        &format!("return {IDLE} && {}", &PRINTABLE[7..]),
        "the first slice",
    )
    .await;
}

/// Closes the first-run guide, which a fresh browser profile shows.
async fn close_guide(c: &Client) {
    wait_js(
        c,
        "return document.getElementById('guide').open",
        "the first-run guide",
    )
    .await;
    click(c, "guide-close").await;
    wait_js(
        c,
        "return !document.getElementById('guide').open",
        "the guide to close",
    )
    .await;
}

/// Picks `file` in the import button's file chooser and waits for the
/// import's preview dialog; `shape` picks a shape (0: the first), then
/// "Use this path" replaces the trajectory. Returns the dialog's count
/// line.
/// Chooses `file` in the page's file input `id`.
async fn choose_file(c: &Client, id: &str, file: &Path) {
    c.find(fantoccini::Locator::Id(id))
        .await
        .unwrap()
        .send_keys(file.to_str().unwrap())
        .await
        .unwrap();
}

async fn import_file(c: &Client, file: &Path, shape: usize) -> String {
    choose_file(c, "import-file", file).await;
    wait_js(
        c,
        "return document.getElementById('import-dialog').open",
        "the import preview",
    )
    .await;
    set_value(c, "im-pick", &shape.to_string()).await;
    let count = js(c, "return document.getElementById('im-count').textContent").await;
    click(c, "im-use").await;
    count.as_str().unwrap().to_string()
}

/// Whether the page is idle: no slice in flight or waiting.
const IDLE: &str =
    "!window.sweepclay.inFlight && !window.sweepclay.pending && !window.sweepclay.settling";

async fn drag(c: &Client, from: (f64, f64), by: (f64, f64), steps: usize) {
    let mut m = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: from.0.round(),
            y: from.1.round(),
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        });
    // Moves 40 ms apart, resting half a second after every fifth: a rest
    // is a pause longer than the drag's own gaps (docs/MODELER.md), so a
    // drag that rests re-slices there.
    for k in 1..=steps {
        let f = k as f64 / steps as f64;
        m = m.then(PointerAction::MoveTo {
            duration: Some(Duration::from_millis(40)),
            x: (from.0 + by.0 * f).round(),
            y: (from.1 + by.1 * f).round(),
        });
        if k % 5 == 0 {
            m = m.pause(Duration::from_millis(500));
        }
    }
    m = m.then(PointerAction::Up {
        button: MOUSE_BUTTON_LEFT,
    });
    c.perform_actions(m).await.unwrap();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn draw_preview_and_download_verified_gcode() {
    let tmp = tempfile::tempdir().unwrap();
    let downloads = tmp.path().join("downloads");
    std::fs::create_dir_all(&downloads).unwrap();
    let Some((_driver, c)) = start_browser(&downloads, &tmp.path().join("profile")).await else {
        return;
    };
    // SWEEPCLAY_URL points the test at a running `sweepclay serve` (e.g. a
    // release build, to measure the round trip users get).
    let base = match std::env::var("SWEEPCLAY_URL") {
        Ok(url) => url.trim_end_matches('/').to_string(),
        Err(_) => {
            let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
            let base = format!("http://{}", listener.local_addr().unwrap());
            tokio::spawn(async move {
                axum::serve(listener, sweepclay_web::router(Default::default()))
                    .await
                    .unwrap()
            });
            base
        }
    };

    c.goto(&format!("{base}/?example=t1")).await.unwrap();
    close_guide(&c).await;
    // t1: 18,432 samples, verified printable.
    let before = wait_js(&c, SAMPLES, "the statistics").await;
    assert_eq!(before, "18,432");
    wait_js(&c, PRINTABLE, "the verdict on t1").await;
    assert_eq!(js(&c, "return window.sweepclayErrors").await, json!([]));
    // The clay in ml and g, and the planner's time.
    let clay = js(
        &c,
        "return document.querySelector('[data-stat=\"clay\"]').textContent",
    )
    .await;
    assert_eq!(clay, json!("88.8 ml, 169 g"));
    let time = js(
        &c,
        "return document.querySelector('[data-stat=\"printing time\"]').textContent",
    )
    .await;
    assert_eq!(time, json!("10.7 min"));

    // Drag the top point of the end profile 40 px up: the design grows.
    let top = point_at(&c, 1, "ed.points.length - 1").await;
    let n0 = js(&c, "return window.sweepclay.roundTrips.length")
        .await
        .as_u64()
        .unwrap();
    drag(&c, top, (0.0, -40.0), 20).await;
    let after = wait_js(
        &c,
        &format!("const s = (() => {{ {SAMPLES} }})(); return s !== {before} && !window.sweepclay.inFlight && !window.sweepclay.pending ? s : null"),
        "the statistics to change after the drag",
    )
    .await;
    let grown: f64 = after.as_str().unwrap().replace(',', "").parse().unwrap();
    assert!(grown > 18_432.0, "{after}");
    let height = js(
        &c,
        "return window.sweepclay.design.profile_end.control_points.at(-1)[1]",
    )
    .await;
    assert!(height.as_f64().unwrap() > 102.5, "{height}");

    // Round trips of the live re-slices during the drag (t1-sized designs).
    let rts = js(
        &c,
        &format!("return window.sweepclay.roundTrips.slice({n0}).map(r => [r.ms, r.server_ms, r.request_ms, r.render_ms])"),
    )
    .await;
    let mut ms: Vec<f64> = rts
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r[0].as_f64().unwrap())
        .collect();
    let mut server: Vec<f64> = rts
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r[1].as_f64().unwrap())
        .collect();
    assert!(ms.len() >= 3, "the drag re-sliced only {} times", ms.len());
    let median = |i: usize| {
        let mut v: Vec<f64> = rts
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r[i].as_f64().unwrap())
            .collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    ms.sort_by(f64::total_cmp);
    server.sort_by(f64::total_cmp);
    eprintln!(
        "live re-slices during the drag: {} round trips (edit → preview drawn), median {:.1} ms, max {:.1} ms; medians: server slicing {:.1} ms, request with transfer and parsing {:.1} ms, drawing {:.1} ms",
        ms.len(),
        ms[ms.len() / 2],
        ms[ms.len() - 1],
        server[server.len() / 2],
        median(2),
        median(3),
    );

    // Undo restores t1; redo brings the edit back.
    c.execute("document.body.dispatchEvent(new KeyboardEvent('keydown', {key: 'z', ctrlKey: true, bubbles: true}))", vec![])
        .await
        .unwrap();
    wait_js(
        &c,
        &format!("const s = (() => {{ {SAMPLES} }})(); return s === {before}"),
        "undo",
    )
    .await;
    c.execute("document.body.dispatchEvent(new KeyboardEvent('keydown', {key: 'Z', ctrlKey: true, shiftKey: true, bubbles: true}))", vec![])
        .await
        .unwrap();
    wait_js(
        &c,
        &format!("const s = (() => {{ {SAMPLES} }})(); return s === {after}"),
        "redo",
    )
    .await;

    // A reload keeps the design (autosave) and its undo history; the
    // guide does not come back.
    c.refresh().await.unwrap();
    wait_js(
        &c,
        &format!("const s = (() => {{ {SAMPLES} }})(); return s === {after}"),
        "the autosaved design after a reload",
    )
    .await;
    assert_eq!(
        js(&c, "return document.getElementById('guide').open").await,
        json!(false)
    );
    click(&c, "undo").await;
    wait_js(
        &c,
        &format!("const s = (() => {{ {SAMPLES} }})(); return s === {before}"),
        "undo after the reload",
    )
    .await;
    click(&c, "redo").await;
    wait_js(
        &c,
        &format!("const s = (() => {{ {SAMPLES} }})(); return s === {after}"),
        "redo after the reload",
    )
    .await;

    // Coloured by stability (the default), a screenshot for the README.
    set_value(&c, "colour-by", "stability").await;
    wait_js(&c, PRINTABLE, "the verdict on the edited design").await;
    if let Ok(path) = std::env::var("SWEEPCLAY_SCREENSHOT") {
        let png = c.screenshot().await.unwrap();
        std::fs::write(&path, png).unwrap();
        eprintln!("screenshot written to {path}");
    }

    // Download the G-code and check it independently.
    let file = download_gcode(&c, &downloads, "no G-code was downloaded").await;
    // The design's own name, spaces kept.
    assert_eq!(file.file_name().unwrap(), "t1 wave ring.gcode");
    // A name in any script keeps its letters in the file name; only what
    // no file system takes is replaced.
    set_value(&c, "name", "my sail édition #2: «vase»").await;
    click(&c, "save").await;
    let want = downloads.join("my sail édition #2_ «vase».json");
    let deadline = Instant::now() + Duration::from_secs(20);
    // The file may exist before the browser has written it whole.
    let saved: Value = loop {
        if let Ok(v) = std::fs::read_to_string(&want)
            .map_err(|e| e.to_string())
            .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
        {
            break v;
        }
        assert!(
            Instant::now() < deadline,
            "no {}: {:?}",
            want.display(),
            std::fs::read_dir(&downloads).unwrap().collect::<Vec<_>>()
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    assert_eq!(saved["name"], "my sail édition #2: «vase»");
    set_value(&c, "name", "t1 wave ring").await;
    let text = std::fs::read_to_string(&file).unwrap();
    let printer = sweepclay_core::Printer::preset("cerambot-plus").unwrap();
    let report = sweepclay_check::check(&text, &sweepclay_plan::printer_check(&printer));
    assert!(report.printable, "{:?}", report.failures);
    assert!(report.extruding_moves as f64 > grown - 2.0);

    // Import a wave drawn through the middle of the sheet: the page picks
    // the offset across the path and says so; it slices printable. Back
    // to offsets from the centre, the error names the way out.
    let svg = tmp.path().join("wave.svg");
    std::fs::write(
        &svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="120mm" height="60mm" viewBox="0 0 120 60"><path d="M 0 30 C 30 0, 30 0, 60 30 S 90 60, 120 30"/></svg>"#,
    )
    .unwrap();
    import_file(&c, &svg, 0).await;
    wait_js(
        &c,
        "return window.sweepclay.design.trajectory.offset === 'normal' && document.getElementById('offset').value === 'normal'",
        "the imported wave with offsets across the path",
    )
    .await;
    let note = wait_js(
        &c,
        "return document.querySelector('#status .note')?.textContent || null",
        "the note on the offset",
    )
    .await;
    assert!(note.as_str().unwrap().contains("perpendicular"), "{note}");
    wait_js(
        &c,
        "return !window.sweepclay.inFlight && !window.sweepclay.pending && document.getElementById('verdict').dataset.printable === 'true'",
        "the verdict on the imported wave",
    )
    .await;
    set_value(&c, "offset", "radial").await;
    let err = error_text(&c, "the error for a radial wave through o").await;
    assert!(
        err.as_str().unwrap().contains("\"offset\": \"normal\""),
        "{err}"
    );

    // The base point of a profile stays: a real double-click on it (the
    // delete gesture) leaves it, and the design, as they were.
    let before = js(
        &c,
        "return JSON.stringify(window.sweepclay.design.profile_start)",
    )
    .await;
    let base_pt = point_at(&c, 0, "0").await;
    let click = |x: f64, y: f64| {
        MouseActions::new("mouse".into())
            .then(PointerAction::MoveTo {
                duration: None,
                x: x.round(),
                y: y.round(),
            })
            .then(PointerAction::Down {
                button: MOUSE_BUTTON_LEFT,
            })
            .then(PointerAction::Up {
                button: MOUSE_BUTTON_LEFT,
            })
            .then(PointerAction::Down {
                button: MOUSE_BUTTON_LEFT,
            })
            .then(PointerAction::Up {
                button: MOUSE_BUTTON_LEFT,
            })
    };
    c.perform_actions(click(base_pt.0, base_pt.1))
        .await
        .unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(
        js(
            &c,
            "return JSON.stringify(window.sweepclay.design.profile_start)"
        )
        .await,
        before,
        "the base point was deleted"
    );

    // The parameters in a potter's words: overlap in %, a tooltip with
    // the default on each, and an error that blames the field changed (a
    // layer height above the max breaks the max's range, but it is the
    // layer height the user typed).
    assert_eq!(
        js(
            &c,
            "return Number(document.getElementById('p-overlap').value).toFixed(2)"
        )
        .await,
        json!("66.67")
    );
    let tip = js(&c, "return document.getElementById('p-spacing').title").await;
    assert!(tip.as_str().unwrap().contains("(default 1.1 mm)"), "{tip}");
    set_value(&c, "p-overlap", "70").await;
    wait_js(
        &c,
        "return window.sweepclay.design.params.overlap === 0.7 && !window.sweepclay.inFlight && !window.sweepclay.pending",
        "overlap 70 % as 0.7",
    )
    .await;
    set_value(&c, "p-layer_height", "3").await;
    let err = error_text(&c, "the error for a layer height over the max").await;
    let err = err.as_str().unwrap();
    assert!(
        err.starts_with("layer height 3 mm: ") && err.contains("max layer height"),
        "{err}"
    );
    assert!(!err.contains("params."), "{err}");
    assert_eq!(
        js(
            &c,
            "return [...document.querySelectorAll('#params input.bad')].map(i => i.id)"
        )
        .await,
        json!(["p-layer_height"])
    );

    // A vessel: from the low wall t5, import a circle from a drawing
    // program; the page closes the trajectory; three floor layers; the
    // verdict is printable and the downloaded G-code, floor and spiral in
    // one run, checks.
    set_value(&c, "example", "t5").await;
    wait_js(
        &c,
        "return window.sweepclay.design.name.startsWith('t5') && !window.sweepclay.design.trajectory.closed && document.getElementById('p-floor_layers').disabled",
        "the open wall t5",
    )
    .await;
    let cup = tmp.path().join("cup.svg");
    std::fs::write(
        &cup,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100"><circle cx="50" cy="50" r="30"/></svg>"#,
    )
    .unwrap();
    import_file(&c, &cup, 0).await;
    wait_js(
        &c,
        "return window.sweepclay.design.trajectory.closed === true && document.getElementById('closed').checked && !document.getElementById('p-floor_layers').disabled",
        "the imported circle as a closed trajectory",
    )
    .await;
    set_value(&c, "offset", "radial").await;
    set_value(&c, "p-floor_layers", "3").await;
    wait_js(
        &c,
        "return window.sweepclay.design.params.floor_layers === 3 && !window.sweepclay.inFlight && !window.sweepclay.pending && document.getElementById('verdict').dataset.printable === 'true'",
        "the verdict on the vessel",
    )
    .await;
    if let Ok(path) = std::env::var("SWEEPCLAY_VESSEL_SCREENSHOT") {
        tokio::time::sleep(Duration::from_millis(500)).await;
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
        eprintln!("vessel screenshot written to {path}");
    }
    for f in std::fs::read_dir(&downloads).unwrap() {
        std::fs::remove_file(f.unwrap().path()).unwrap();
    }
    let file = download_gcode(&c, &downloads, "no vessel G-code was downloaded").await;
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.contains(";TYPE:Bottom solid infill") && text.contains("floor_layers=3"));
    let report = sweepclay_check::check(&text, &sweepclay_plan::printer_check(&printer));
    assert!(report.printable, "{:?}", report.failures);
    assert_eq!(report.extrusion_runs, 1);
    // A pot whose flare the support-free correction narrows by 16 mm:
    // the verdict says it is reshaped, and the profile editor draws the
    // profile as printed beside the drawn one (docs/MODELER.md).
    let flared = tmp.path().join("flared.json");
    std::fs::write(
        &flared,
        r#"{"sweepclay":1,"name":"flared pot","profile_start":{"control_points":[[0,0],[0,200],[140,240]]},
        "trajectory":{"control_points":[[50,0],[35.4,35.4],[0,50],[-35.4,35.4],[-50,0],[-35.4,-35.4],[0,-50],[35.4,-35.4]],"closed":true,"offset":"normal"},
        "printer":"wasp-40100-clay"}"#,
    )
    .unwrap();
    choose_file(&c, "open-file", &flared).await;
    let verdict = wait_js(
        &c,
        "const v = document.getElementById('verdict'); return window.sweepclay.design.name === 'flared pot' && !window.sweepclay.inFlight && !window.sweepclay.pending && v.classList.contains('warn') ? v.textContent : null",
        "the reshaped verdict",
    )
    .await;
    assert!(
        verdict
            .as_str()
            .unwrap()
            .starts_with("⚠ printable, but reshaped: up to ")
            && verdict.as_str().unwrap().contains("narrower than drawn"),
        "{verdict}"
    );
    let printed = js(
        &c,
        "return (window.sweepclay.printed.profile_start || []).length",
    )
    .await;
    assert!(printed.as_u64().unwrap() > 10, "{printed}");
    if let Ok(path) = std::env::var("SWEEPCLAY_RESHAPED_SCREENSHOT") {
        tokio::time::sleep(Duration::from_millis(500)).await;
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
        eprintln!("reshaped screenshot written to {path}");
    }
    no_page_errors_and_close(c).await;
}

/// A server for one test: `SWEEPCLAY_URL`, or one in this process.
async fn server() -> String {
    match std::env::var("SWEEPCLAY_URL") {
        Ok(url) => url.trim_end_matches('/').to_string(),
        Err(_) => {
            let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
            let base = format!("http://{}", listener.local_addr().unwrap());
            tokio::spawn(async move {
                axum::serve(listener, sweepclay_web::router(Default::default()))
                    .await
                    .unwrap()
            });
            base
        }
    }
}

/// The bounding boxes (`[left, top, right, bottom]`, viewport px) of the
/// elements a selector finds that are shown.
async fn boxes(c: &Client, selector: &str) -> Vec<(String, [f64; 4])> {
    let v = c
        .execute(
            "return [...document.querySelectorAll(arguments[0])].filter(e => e.offsetParent !== null).map(e => { const r = e.getBoundingClientRect(); return [e.id || e.tagName, [r.left, r.top, r.right, r.bottom]]; })",
            vec![json!(selector)],
        )
        .await
        .unwrap();
    serde_json::from_value(v).unwrap()
}

/// Fails if two of the boxes overlap (by more than a pixel of rounding).
fn no_overlap(what: &str, b: &[(String, [f64; 4])]) {
    for (i, (na, a)) in b.iter().enumerate() {
        for (nb, q) in &b[i + 1..] {
            let x = a[2].min(q[2]) - a[0].max(q[0]);
            let y = a[3].min(q[3]) - a[1].max(q[1]);
            assert!(
                x <= 1.0 || y <= 1.0,
                "{what}: {na} {a:?} overlaps {nb} {q:?}"
            );
        }
    }
}

/// The page tells the truth and never gets stuck: the verdict race and
/// the out-of-date marking, a drag released over another editor, a print
/// too big for the printer shown with its outside in red, a custom
/// printer, imports (a CSV with comments, a dense curve simplified, one
/// sub-path picked), an autosave that does not slice, and the layout at
/// phone and tablet sizes.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn truthful_state_imports_printers_and_phones() {
    let tmp = tempfile::tempdir().unwrap();
    let downloads = tmp.path().join("downloads");
    std::fs::create_dir_all(&downloads).unwrap();
    let Some((_driver, c)) = start_browser(&downloads, &tmp.path().join("profile")).await else {
        return;
    };
    let base = server().await;
    c.goto(&format!("{base}/?example=t2")).await.unwrap();
    close_guide(&c).await;
    wait_js(&c, PRINTABLE, "the verdict on t2").await;

    // The verdict race: spacing changed, then within 250 ms a layer height
    // of 0. The error stands alone: no ✓ beside it, the preview and the
    // statistics marked out of date.
    set_value(&c, "p-spacing", "1.0").await;
    tokio::time::sleep(Duration::from_millis(40)).await;
    set_value(&c, "p-layer_height", "0").await;
    let err = error_text(&c, "the error for layer height 0").await;
    assert!(err.as_str().unwrap().starts_with("layer height"), "{err}");
    tokio::time::sleep(Duration::from_millis(700)).await;
    let state = js(
        &c,
        "return [document.getElementById('verdict').textContent, document.getElementById('preview').classList.contains('stale'), document.getElementById('stats').classList.contains('stale'), document.getElementById('stale-note').hidden]",
    )
    .await;
    assert!(!state[0].as_str().unwrap().contains('✓'), "{state}");
    assert_eq!(
        state.as_array().unwrap()[1..],
        [json!(true), json!(true), json!(false)],
        "{state}"
    );
    // A decimal comma is a decimal, not 15; a number with two commas is
    // refused by name.
    set_value(&c, "p-layer_height", "1,5").await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.params.layer_height === 1.5"),
        "a layer height of 1,5 read as 1.5",
    )
    .await;
    // (Once its slice is back: a good slice's answer clears the errors,
    // and one arriving after the next field error would clear that too.)
    set_value(&c, "p-layer_height", "1,2,5").await;
    let err = error_text(&c, "the error for 1,2,5").await;
    assert!(err.as_str().unwrap().contains("not a number"), "{err}");
    set_value(&c, "p-layer_height", "1.25").await;
    wait_js(&c, PRINTABLE, "the verdict once the layer height is back").await;
    assert_eq!(
        js(&c, "return document.getElementById('preview').classList.contains('stale') || !document.getElementById('stale-note').hidden").await,
        json!(false)
    );

    // A drag released over the next editor ends there: moving over the
    // first editor afterwards, with no button down, changes nothing.
    let from = point_at(&c, 0, "2").await;
    let to = point_at(&c, 1, "2").await;
    drag(&c, from, (to.0 - from.0, to.1 - from.1), 8).await;
    wait_js(&c, &format!("return {IDLE}"), "the slice after the drag").await;
    let held = js(&c, "return JSON.stringify(window.sweepclay.design)").await;
    let wander = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: from.0.round(),
            y: (from.1 + 30.0).round(),
        })
        .then(PointerAction::MoveTo {
            duration: Some(Duration::from_millis(200)),
            x: (from.0 + 25.0).round(),
            y: (from.1 - 30.0).round(),
        });
    c.perform_actions(wander).await.unwrap();
    tokio::time::sleep(Duration::from_millis(200)).await;
    assert_eq!(
        js(
            &c,
            "return window.sweepclay.editors.every(e => e.drag === null)"
        )
        .await,
        json!(true)
    );
    assert_eq!(
        js(&c, "return JSON.stringify(window.sweepclay.design)").await,
        held
    );

    // Numeric entry and the touch buttons: select the third point of the
    // path, type a new x, add a point after it, delete that point.
    js(
        &c,
        "const ed = window.sweepclay.editors[2]; ed.selected = 2; ed.told(); return 0",
    )
    .await;
    let x0 = js(
        &c,
        "return window.sweepclay.design.trajectory.control_points[2][0]",
    )
    .await;
    let x1 = x0.as_f64().unwrap() + 3.0;
    set_value(&c, "pb-x", &x1.to_string()).await;
    assert_eq!(
        js(
            &c,
            "return window.sweepclay.design.trajectory.control_points[2][0]"
        )
        .await,
        json!(x1)
    );
    let n = js(
        &c,
        "return window.sweepclay.design.trajectory.control_points.length",
    )
    .await;
    click(&c, "pb-add").await;
    assert_eq!(
        js(
            &c,
            "return window.sweepclay.design.trajectory.control_points.length"
        )
        .await,
        json!(n.as_u64().unwrap() + 1)
    );
    click(&c, "pb-del").await;
    assert_eq!(
        js(
            &c,
            "return window.sweepclay.design.trajectory.control_points.length"
        )
        .await,
        n
    );
    // The base point of a profile cannot be deleted with the button.
    js(
        &c,
        "const ed = window.sweepclay.editors[0]; ed.selected = 0; ed.told(); return 0",
    )
    .await;
    assert_eq!(
        js(&c, "return document.getElementById('pb-del').disabled").await,
        json!(true)
    );

    // Too big for the printer: the preview shows it with the part outside
    // in red, the message says how much too big in the user's words, and
    // the preview is the current design, not an old one.
    set_value(&c, "example", "t1").await;
    wait_js(&c, PRINTABLE, "the verdict on t1").await;
    set_value(&c, "p-printer", "cerambot-mini").await;
    let err = error_text(&c, "the error for a print too big").await;
    assert!(
        err.as_str().unwrap().contains("mm too") && err.as_str().unwrap().contains("cerambot-mini"),
        "{err}"
    );
    assert!(!err.as_str().unwrap().contains('`'), "{err}");
    let shown = js(
        &c,
        "return [window.sweepclay.view.outsideCount > 0, document.getElementById('preview').classList.contains('stale'), document.getElementById('verdict').dataset.printable]",
    )
    .await;
    assert_eq!(shown, json!([true, false, "false"]));

    // A custom printer, kept in the browser: big enough for t1.
    open_printer_dialog(&c).await;
    for (id, v) in [
        ("pr-name", "my big printer"),
        ("pr-bv0", "300"),
        ("pr-bv1", "300"),
        ("pr-bv2", "300"),
        ("pr-o0", "150"),
        ("pr-o1", "150"),
    ] {
        c.execute(
            "document.getElementById(arguments[0]).value = arguments[1]",
            vec![json!(id), json!(v)],
        )
        .await
        .unwrap();
    }
    click(&c, "pr-save").await;
    wait_js(&c, PRINTABLE, "the verdict on the custom printer").await;
    assert_eq!(
        js(&c, "return [window.sweepclay.design.printer.name, window.sweepclay.design.printer.build_volume, document.getElementById('p-printer').value]").await,
        json!(["my big printer", [300, 300, 300], "kept:my big printer"])
    );

    // A CSV with comments before and inside its data, and a header; it is
    // centred on o, as an SVG is.
    let csv = tmp.path().join("wall.csv");
    std::fs::write(
        &csv,
        "# drawn by hand\n# mm\nx,y\n0,0\n# the middle\n60,20\n120,0\n",
    )
    .unwrap();
    import_file(&c, &csv, 0).await;
    let pts = wait_js(
        &c,
        "const p = window.sweepclay.design.trajectory.points; return p && p.length === 3 ? p : null",
        "the CSV's three points",
    )
    .await;
    assert_eq!(pts, json!([[-60, -10], [0, 10], [60, -10]]));

    // A dense curve (600 points from a drawing program) is offered as a
    // few editable points within the tolerance shown.
    let wave: Vec<String> = (0..600)
        .map(|i| {
            let t = i as f64 / 599.0;
            format!(
                "{:.3},{:.3}",
                20.0 + 160.0 * t,
                60.0 + 25.0 * (std::f64::consts::TAU * t).sin()
            )
        })
        .collect();
    let dense = tmp.path().join("dense.svg");
    std::fs::write(
        &dense,
        format!(r#"<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="120mm" viewBox="0 0 200 120"><polyline points="{}"/></svg>"#, wave.join(" ")),
    )
    .unwrap();
    let count = import_file(&c, &dense, 0).await;
    assert!(
        count.starts_with("600 → ") && count.contains("within 0.2 mm"),
        "{count}"
    );
    let kept: usize = count["600 → ".len()..]
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((5..100).contains(&kept), "{count}");
    wait_js(
        &c,
        &format!(
            "const p = window.sweepclay.design.trajectory.points; return p && p.length === {kept}"
        ),
        "the simplified wave",
    )
    .await;
    // The simplified points stay within the tolerance of the drawn curve:
    // the wave's crest is still 25 mm above its middle.
    let crest = js(&c, "return Math.max(...window.sweepclay.design.trajectory.points.map(p => p[1])) - Math.min(...window.sweepclay.design.trajectory.points.map(p => p[1]))").await;
    assert!((crest.as_f64().unwrap() - 50.0).abs() < 0.4, "{crest}");

    // Two shapes in one path: the second is picked.
    let two = tmp.path().join("two.svg");
    std::fs::write(
        &two,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" viewBox="0 0 200 200"><path d="M 10 100 L 190 100 M 100 40 L 100 160 L 160 160"/></svg>"#,
    )
    .unwrap();
    import_file(&c, &two, 1).await;
    wait_js(
        &c,
        "const p = window.sweepclay.design.trajectory.points; return p && p.length === 3",
        "the second sub-path",
    )
    .await;
    assert_eq!(js(&c, "return window.sweepclayErrors").await, json!([]));

    // An autosave that does not slice (a mistyped key) opens with a way
    // out, and the way out works. (The page saves its own a moment after
    // its last change: that moment passes first.)
    tokio::time::sleep(Duration::from_millis(500)).await;
    c.execute(
        "const d = {sweepclay: 1, name: 'typo', profile_start: {control_points: [[0,0],[0,30]]}, profile_end: {control_points: [[0,0],[0,30]]}, trajectory: {control_points: [[-40,20],[0,40],[40,20]]}, params: {layer_hieght: 1}}; localStorage.setItem('sweepclay.design.v1', JSON.stringify(d)); localStorage.setItem('sweepclay.history.v1', JSON.stringify({history: [JSON.stringify(d)], at: 0})); sessionStorage.clear();",
        vec![],
    )
    .await
    .unwrap();
    c.goto(&base).await.unwrap();
    wait_js(
        &c,
        "return document.getElementById('escape-example') !== null",
        "the way out of an autosave that does not slice",
    )
    .await;
    click(&c, "escape-example").await;
    wait_js(&c, PRINTABLE, "the first example after the way out").await;
    // The phone's layout is measured on a design with all four editors.
    c.goto(&format!("{base}/?example=t1")).await.unwrap();
    wait_js(&c, &format!("return {IDLE} && {}", &PRINTABLE[7..]), "t1").await;

    // A phone: tabs, one panel at a time; nothing overlaps, every editor
    // and the 3D view have room, nothing is wider than the screen.
    c.set_window_size(390, 844).await.unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    let vw = js(&c, "return window.innerWidth").await.as_f64().unwrap();
    for tab in ["editors", "preview", "side"] {
        c.execute(
            "document.querySelector(`#tabs button[data-tab=${arguments[0]}]`).click()",
            vec![json!(tab)],
        )
        .await
        .unwrap();
        tokio::time::sleep(Duration::from_millis(200)).await;
        let b = boxes(&c, "header, #tabs, #editors canvas, #point-bar, #view3d, #view-controls, #stats, #verdict, #params").await;
        no_overlap(tab, &b);
        let wide = js(&c, "return document.documentElement.scrollWidth")
            .await
            .as_f64()
            .unwrap();
        assert!(
            wide <= vw + 1.0,
            "{tab}: the page is {wide} px wide on a {vw} px screen"
        );
        assert!(
            b.iter().any(|(n, _)| n == "tabs"),
            "{tab}: no tabs on a phone: {b:?}"
        );
        let sizes: Vec<&(String, [f64; 4])> = b
            .iter()
            .filter(|(n, _)| n.starts_with("ed-") || n == "view3d")
            .collect();
        match tab {
            "editors" => assert_eq!(sizes.len(), 4, "{b:?}"),
            "preview" => assert_eq!(sizes.len(), 1, "{b:?}"),
            _ => assert!(sizes.is_empty(), "{b:?}"),
        }
        for (n, r) in sizes {
            assert!(
                r[2] - r[0] > 300.0 && r[3] - r[1] > 200.0,
                "{tab}: {n} is {r:?}"
            );
        }
        if let Ok(dir) = std::env::var("SWEEPCLAY_PHONE_SCREENSHOTS") {
            let path = format!("{dir}/phone-{tab}.png");
            std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
            eprintln!("phone screenshot written to {path}");
        }
    }
    // A tablet: one column, the editors above the 3D view and the side.
    c.set_window_size(768, 1024).await.unwrap();
    // The resize lands when the page has laid itself out again (slow on a
    // loaded machine): the phone's tabs are gone then.
    wait_js(
        &c,
        "return document.getElementById('tabs').offsetParent === null",
        "the tablet layout",
    )
    .await;
    tokio::time::sleep(Duration::from_millis(300)).await;
    let b = boxes(
        &c,
        "header, #editors canvas, #point-bar, #view3d, #view-controls, #stats, #verdict, #params",
    )
    .await;
    no_overlap("tablet", &b);
    assert_eq!(
        js(&c, "return document.getElementById('tabs').offsetParent").await,
        Value::Null
    );
    assert_eq!(
        b.iter()
            .filter(|(n, _)| n.starts_with("ed-") || n == "view3d")
            .count(),
        5,
        "{b:?}"
    );
    no_page_errors_and_close(c).await;
}

/// The speed budget of docs/MODELER.md, measured (not a pass/fail timing:
/// run by `scripts/bench-modeler`, which prints the figures): on t1 and
/// the vase, drags of the end profile's top point at 60 pointer moves a
/// second; every figure counts from the pointer event's own `timeStamp`
/// (so its wait in the browser's queue counts) to the painted frame: the
/// edited curve, the sliced preview of the oldest edit it shows, and the
/// last edit's verdict.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "a measurement: scripts/bench-modeler runs it"]
async fn modeler_speed_budget() {
    let Some(Session {
        tmp: _tmp,
        downloads: _,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    let rounds: usize = std::env::var("SWEEPCLAY_BENCH_DRAGS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let q = |v: &[f64], f: f64| v[((v.len() as f64 - 1.0) * f).round() as usize];
    // SWEEPCLAY_BENCH_LOAD=N: N threads spinning beside the browser and
    // the server for the whole run, a machine busy with other work.
    let load: usize = std::env::var("SWEEPCLAY_BENCH_LOAD")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0);
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let spinners: Vec<_> = (0..load)
        .map(|_| {
            let stop = stop.clone();
            std::thread::spawn(move || {
                let mut x = 0u64;
                while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                    x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
                }
            })
        })
        .collect();
    for example in ["t1", "vase"] {
        c.goto(&format!("{base}/?example={example}")).await.unwrap();
        if example == "t1" {
            close_guide(&c).await;
        }
        wait_js(&c, PRINTABLE, "the verdict on the example").await;
        // The vase is made a one-profile pot (its two profiles are one
        // shape), so that a drag keeps its rim level.
        let editor = if example == "vase" {
            set_checked(&c, "one-profile").await;
            wait_js(&c, &format!("return {IDLE} && !window.sweepclay.design.profile_end && document.getElementById('verdict').dataset.printable === 'true'"), "the vase as a pot").await;
            0
        } else {
            1
        };
        let (mut edit, mut preview, mut verdict, mut input, mut gap, mut work) = (
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
            Vec::new(),
        );
        let mut rests = 0.0;
        for r in 0..rounds {
            js(&c, "const s = window.sweepclay; s.roundTrips = []; s.verdictTimes = []; s.editTimes = []; s.frames.work = []; s.frames.gap = []; s.frames.input = []; return 0").await;
            let top = point_at(&c, editor, "ed.points.length - 1").await;
            let dy = if r % 2 == 0 { -30.0 } else { 30.0 };
            let mut m = MouseActions::new("mouse".into())
                .then(PointerAction::MoveTo {
                    duration: None,
                    x: top.0.round(),
                    y: top.1.round(),
                })
                .then(PointerAction::Down {
                    button: MOUSE_BUTTON_LEFT,
                });
            for k in 1..=60 {
                m = m.then(PointerAction::MoveTo {
                    duration: Some(Duration::from_millis(16)),
                    x: top.0.round(),
                    y: (top.1 + dy * k as f64 / 60.0).round(),
                });
            }
            m = m.then(PointerAction::Up {
                button: MOUSE_BUTTON_LEFT,
            });
            c.perform_actions(m).await.unwrap();
            wait_js(
                &c,
                &format!("return {IDLE} && window.sweepclay.verdictTimes.length > 0"),
                "the verdict after the drag",
            )
            .await;
            let v = js(
                &c,
                "const s = window.sweepclay; return [s.editTimes, s.roundTrips.filter(r => !r.rest).map(r => r.ms), s.verdictTimes.at(-1), s.frames.input, s.frames.gap, s.frames.work, [s.roundTrips.filter(r => r.rest).length]]",
            )
            .await;
            let nums = |k: usize| -> Vec<f64> {
                v[k].as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap())
                    .collect()
            };
            edit.extend(nums(0));
            preview.extend(nums(1));
            verdict.push(v[2].as_f64().unwrap());
            input.extend(nums(3));
            gap.extend(nums(4));
            work.extend(nums(5));
            rests += nums(6)[0];
        }
        for v in [
            &mut edit,
            &mut preview,
            &mut verdict,
            &mut input,
            &mut gap,
            &mut work,
        ] {
            v.sort_by(f64::total_cmp);
        }
        assert!(!edit.is_empty(), "the edited curve was never painted");
        eprintln!(
            "modeler speed ({example}, {rounds} drags of 60 moves at 60 Hz, {load} threads of other work spinning, from each event's timeStamp to the painted frame): the edited curve {} frames, median {:.0} ms, 95th percentile {:.0} ms; the sliced preview after the release {} times, median {:.0} ms, 95th percentile {:.0} ms; the verdict median {:.0} ms, max {:.0} ms; the wait before the page hears an event median {:.0} ms; between frames median {:.0} ms, 95th percentile {:.0} ms; a frame's own work median {:.1} ms, 95th percentile {:.1} ms; {rests} slices sent mid-drag at a rest",
            edit.len(),
            q(&edit, 0.5),
            q(&edit, 0.95),
            preview.len(),
            q(&preview, 0.5),
            q(&preview, 0.95),
            q(&verdict, 0.5),
            verdict[verdict.len() - 1],
            q(&input, 0.5),
            q(&gap, 0.5),
            q(&gap, 0.95),
            q(&work, 0.5),
            q(&work, 0.95),
        );
    }
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    for t in spinners {
        t.join().unwrap();
    }
    c.close().await.unwrap();
}

/// A browser on a fresh profile, a server, and the downloads folder; the
/// browser and the folder go when it is dropped.
struct Session {
    tmp: tempfile::TempDir,
    downloads: PathBuf,
    driver: Driver,
    c: Client,
    base: String,
}

impl Session {
    /// `None` where there is no browser to run (the test then passes, as
    /// the others do: `start_browser` says why).
    async fn start() -> Option<Session> {
        let tmp = tempfile::tempdir().unwrap();
        let downloads = tmp.path().join("downloads");
        std::fs::create_dir_all(&downloads).unwrap();
        let (driver, c) = start_browser(&downloads, &tmp.path().join("profile")).await?;
        let base = server().await;
        Some(Session {
            tmp,
            downloads,
            driver,
            c,
            base,
        })
    }
}

/// Taps the point `at` (page pixels) with a finger: down and up.
async fn tap(c: &Client, at: (f64, f64)) {
    let t = TouchActions::new("finger".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: at.0.round(),
            y: at.1.round(),
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        })
        .then(PointerAction::Up {
            button: MOUSE_BUTTON_LEFT,
        });
    c.perform_actions(t).await.unwrap();
}

/// Scrolls element `id` into view and taps its middle.
async fn tap_id(c: &Client, id: &str) {
    let r = js(
        c,
        &format!("const e = document.getElementById('{id}'); e.scrollIntoView({{block: 'center'}}); const r = e.getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2]"),
    )
    .await;
    tap(c, (r[0].as_f64().unwrap(), r[1].as_f64().unwrap())).await;
}

/// Taps a text field, types `text` over what it held and leaves it (Tab),
/// as a thumb and an on-screen keyboard do.
async fn type_into(c: &Client, id: &str, text: &str) {
    tap_id(c, id).await;
    let e = c.find(fantoccini::Locator::Id(id)).await.unwrap();
    js(
        c,
        &format!("document.getElementById('{id}').select(); return 0"),
    )
    .await;
    e.send_keys(&format!("{text}\u{E004}")).await.unwrap();
}

/// A finger drag from `from` by `by` px in `steps` moves.
async fn finger_drag(c: &Client, from: (f64, f64), by: (f64, f64), steps: usize) {
    let mut t = TouchActions::new("finger".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: from.0.round(),
            y: from.1.round(),
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        });
    for k in 1..=steps {
        let f = k as f64 / steps as f64;
        t = t.then(PointerAction::MoveTo {
            duration: Some(Duration::from_millis(16)),
            x: (from.0 + by.0 * f).round(),
            y: (from.1 + by.1 * f).round(),
        });
    }
    t = t.then(PointerAction::Up {
        button: MOUSE_BUTTON_LEFT,
    });
    c.perform_actions(t).await.unwrap();
}

/// The visible controls smaller than a fingertip (44 px either way): a
/// checkbox counts by its label.
const SMALL_CONTROLS: &str = "return [...document.querySelectorAll('button, select, input, textarea')].filter((e) => e.offsetParent !== null && !e.closest('dialog:not([open])')).map((e) => { const t = e.type === 'checkbox' ? e.closest('label') || e : e; const r = t.getBoundingClientRect(); return [e.id || e.textContent.trim() || e.type, Math.round(r.width), Math.round(r.height)]; }).filter(([, w, h]) => w < 44 || h < 44)";

/// Issue 59, point 6: on a phone the printer dialog's "Calibrate" summary
/// (18 px) and key field (21 px) were under a fingertip; with the
/// keyboard up (the page 508 px tall) the header and tabs took 200 px and
/// a row's error landed under the keyboard. Now every control of the
/// dialog is 44 px, and while a field has the focus the header and tabs
/// step aside and the row's error is on screen.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_printer_dialog_and_a_rows_error_fit_a_phone() {
    let Some(Session {
        driver: _driver,
        c,
        base,
        ..
    }) = Session::start().await
    else {
        return;
    };
    c.set_window_size(390, 844).await.unwrap();
    open_first_slice(&c, &base).await;
    c.execute(
        "document.querySelector('#tabs button[data-tab=side]').click()",
        vec![],
    )
    .await
    .unwrap();
    tap_id(&c, "printer-edit").await;
    wait_js(
        &c,
        "return document.getElementById('printer-dialog').open",
        "the printer dialog",
    )
    .await;
    js(
        &c,
        "document.getElementById('pr-cal').open = true; return 0",
    )
    .await;
    tokio::time::sleep(Duration::from_millis(200)).await;
    let small = js(
        &c,
        "return [...document.querySelectorAll('#printer-dialog summary, #printer-dialog button, #printer-dialog select, #printer-dialog input:not([type=checkbox]), #printer-dialog textarea')].filter((e) => e.offsetParent !== null).map((e) => { const r = e.getBoundingClientRect(); return [e.id || e.textContent.trim().slice(0, 20) || e.type, Math.round(r.width), Math.round(r.height)]; }).filter(([, w, h]) => w < 44 || h < 44)",
    )
    .await;
    assert_eq!(small, json!([]), "the printer dialog: controls under 44 px");
    // An https:// host's certificate: a fingerprint cut short, or one
    // with a plain http:// address, is refused beside the button.
    set_value(&c, "pr-host-kind", "octoprint").await;
    set_value(&c, "pr-host-url", "https://octopi.local").await;
    set_value(&c, "pr-host-cert", "3f:a0:9c").await;
    tap_id(&c, "pr-save").await;
    let said = js(&c, "return document.getElementById('pr-error').textContent").await;
    assert!(said.as_str().unwrap().contains("64 hex digits"), "{said}");
    if let Ok(path) = std::env::var("SWEEPCLAY_PHONE_CERT_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    set_value(&c, "pr-host-url", "http://octopi.local").await;
    set_value(&c, "pr-host-cert", &"3f".repeat(32)).await;
    tap_id(&c, "pr-save").await;
    let said = js(&c, "return document.getElementById('pr-error').textContent").await;
    assert!(said.as_str().unwrap().contains("https://"), "{said}");
    assert!(
        js(&c, "return document.getElementById('printer-dialog').open")
            .await
            .as_bool()
            .unwrap(),
        "a refused entry keeps the dialog open"
    );
    js(
        &c,
        "document.getElementById('printer-dialog').close(); return 0",
    )
    .await;
    // The keyboard up: 508 px of page. A height on the base, refused.
    c.set_window_size(390, 508).await.unwrap();
    c.execute(
        "document.querySelector('#tabs button[data-tab=editors]').click()",
        vec![],
    )
    .await
    .unwrap();
    tap_id(&c, "new-pot").await;
    wait_js(
        &c,
        &format!("return {IDLE} && !window.sweepclay.design.profile_end"),
        "a new pot",
    )
    .await;
    tap_id(&c, "pot-z2").await;
    let e = c.find(fantoccini::Locator::Id("pot-z2")).await.unwrap();
    js(&c, "document.getElementById('pot-z2').select(); return 0").await;
    e.send_keys("0,3").await.unwrap();
    // The change fires while the field keeps the focus (Enter).
    js(
        &c,
        "document.getElementById('pot-z2').dispatchEvent(new Event('change')); return 0",
    )
    .await;
    let at = wait_js(
        &c,
        "const e = document.getElementById('pot-error'); const r = e.getBoundingClientRect(); return e.textContent.length > 0 && [r.top, r.bottom, window.innerHeight, document.getElementById('header-extras').getBoundingClientRect().height, document.activeElement.id]",
        "the error",
    )
    .await;
    let (top, bottom, height) = (
        at[0].as_f64().unwrap(),
        at[1].as_f64().unwrap(),
        at[2].as_f64().unwrap(),
    );
    assert!(top >= 0.0 && bottom <= height, "the error off screen: {at}");
    assert_eq!(at[3], json!(0), "the header stays while typing: {at}");
    if let Ok(path) = std::env::var("SWEEPCLAY_KEYBOARD_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    no_page_errors_and_close(c).await;
}

/// Issue 29's walk: on a 390 × 844 phone, by touch only and by controls a
/// fingertip hits, from "New pot" through the widths at heights to a
/// downloaded G-code that the independent checker passes; and the phone's
/// defects, each checked on the way (a tap then a nudge deletes nothing,
/// a finger takes a point from 18 px, an error shows beside its field on
/// the Settings tab, and a verdict never belongs to an older design).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_pot_on_a_phone_by_touch() {
    let Some(Session {
        tmp: _tmp,
        downloads,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    c.set_window_size(390, 844).await.unwrap();
    c.goto(&base).await.unwrap();
    wait_js(
        &c,
        "return document.getElementById('guide').open",
        "the guide",
    )
    .await;
    tap_id(&c, "guide-close").await;
    wait_js(&c, PRINTABLE, "the first example").await;

    // Every control a finger can hit, on each tab.
    for tab in ["side", "preview", "editors"] {
        c.execute(
            "document.querySelector(`#tabs button[data-tab=${arguments[0]}]`).click()",
            vec![json!(tab)],
        )
        .await
        .unwrap();
        tokio::time::sleep(Duration::from_millis(300)).await;
        let small = js(&c, SMALL_CONTROLS).await;
        assert_eq!(small, json!([]), "{tab}: controls under 44 px");
    }

    // New pot: one profile, a round loop sized to the printer, a floor.
    tap_id(&c, "new-pot").await;
    wait_js(
        &c,
        "const d = window.sweepclay.design; return d.name === 'new pot' && !d.profile_end && d.trajectory.closed && document.getElementById('end-figure').hidden && !document.getElementById('pot-panel').hidden",
        "a new pot in pot mode",
    )
    .await;
    wait_js(
        &c,
        &format!("return {IDLE} && {}", &PRINTABLE[7..]),
        "the new pot prints",
    )
    .await;
    let small = js(&c, SMALL_CONTROLS).await;
    assert_eq!(small, json!([]), "pot mode: controls under 44 px");

    // Widths at heights, typed with a decimal comma, and the height.
    type_into(&c, "pot-w2", "70,5").await;
    wait_js(
        &c,
        "return document.getElementById('pot-w2').value === '70.5'",
        "the width at the third height",
    )
    .await;
    type_into(&c, "pot-height", "80").await;
    wait_js(
        &c,
        "return window.sweepclay.design.profile_start.control_points.at(-1)[1] === 80",
        "the pot 80 mm tall",
    )
    .await;
    type_into(&c, "pot-z2", "0,3").await;
    let err = wait_js(
        &c,
        "return document.getElementById('pot-error').textContent || null",
        "a height on the base refused beside the table",
    )
    .await;
    assert!(
        err.as_str().unwrap().contains("must be above the base"),
        "{err}"
    );
    wait_js(
        &c,
        &format!("return {IDLE} && {}", &PRINTABLE[7..]),
        "the edited pot prints",
    )
    .await;

    // A tap on a point, then a quick nudge: nothing is
    // deleted (two taps used to read as a double-click on the second).
    // The side profile in the middle of the screen, clear of the tabs.
    js(
        &c,
        "document.getElementById('ed-start').scrollIntoView({block: 'center'}); return 0",
    )
    .await;
    let n = js(
        &c,
        "return window.sweepclay.design.profile_start.control_points.length",
    )
    .await;
    // Two taps close together are what the browser makes a double-click
    // of: a tap on a point, then a nudge of the same or a near point.
    let p2 = point_at(&c, 0, "2").await;
    tap(&c, p2).await;
    finger_drag(&c, p2, (8.0, 0.0), 2).await;
    tokio::time::sleep(Duration::from_millis(400)).await;
    assert_eq!(
        js(
            &c,
            "return window.sweepclay.design.profile_start.control_points.length"
        )
        .await,
        n,
        "a tap and a nudge deleted a point"
    );
    // A finger takes a point from 18 px away.
    let before = js(
        &c,
        "return window.sweepclay.design.profile_start.control_points[2][1]",
    )
    .await;
    let p2 = point_at(&c, 0, "2").await;
    finger_drag(&c, (p2.0 + 18.0, p2.1), (0.0, -20.0), 5).await;
    wait_js(
        &c,
        &format!("return window.sweepclay.design.profile_start.control_points[2][1] !== {before}"),
        "the point taken by a finger 18 px away",
    )
    .await;

    // A verdict for an older design never shows: the height alternates
    // between too tall for the printer and fitting, 5–20 ms apart (an
    // answer for one comes back while the next waits); the last one fits
    // and no ✗ is ever shown while it is the design in the editors.
    // Every verdict shown is noted with the design in the editors then.
    js(&c, "window.__verdicts = []; const v = document.getElementById('verdict'); new MutationObserver(() => window.__verdicts.push([v.dataset.printable, window.sweepclay.design.profile_start.control_points.at(-1)[1]])).observe(v, {attributes: true, childList: true, subtree: true, characterData: true}); return 0").await;
    js(&c, "const e = document.getElementById('pot-height'); let k = 0; const step = () => { e.value = k % 2 === 0 ? '400' : '120'; e.dispatchEvent(new Event('change')); k++; if (k < 16) setTimeout(step, 5 + 5 * (k % 4)); }; step(); return 0").await;
    wait_js(&c, "return document.getElementById('pot-height').value === '120' && window.sweepclay.design.profile_start.control_points.at(-1)[1] === 120 || null", "the last height typed").await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.profile_start.control_points.at(-1)[1] === 120 && document.getElementById('verdict').dataset.printable !== ''"),
        "the verdict on the last height",
    )
    .await;
    assert_eq!(
        js(&c, PRINTABLE).await,
        json!(true),
        "{}",
        js(&c, "return document.getElementById('verdict').textContent").await
    );
    let wrong = js(
        &c,
        "return window.__verdicts.filter(([p, z]) => p === 'false' && z === 120)",
    )
    .await;
    assert_eq!(
        wrong,
        json!([]),
        "a ✗ for the 400 mm design shown over the 120 mm one"
    );

    // An error on the Settings tab shows beside its field.
    c.execute(
        "document.querySelector('#tabs button[data-tab=side]').click()",
        vec![],
    )
    .await
    .unwrap();
    type_into(&c, "p-layer_height", "9").await;
    let beside = wait_js(
        &c,
        "const e = document.getElementById('err-layer_height'); return e && e.offsetParent !== null ? e.textContent : null",
        "the layer height's error beside it",
    )
    .await;
    assert!(
        beside.as_str().unwrap().contains("layer height"),
        "{beside}"
    );
    type_into(&c, "p-layer_height", "1,25").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && !document.getElementById('err-layer_height') && {}",
            &PRINTABLE[7..]
        ),
        "the error gone with the layer height back",
    )
    .await;

    if let Ok(dir) = std::env::var("SWEEPCLAY_PHONE_SCREENSHOTS") {
        for tab in ["editors", "preview"] {
            c.execute(
                "document.querySelector(`#tabs button[data-tab=${arguments[0]}]`).click()",
                vec![json!(tab)],
            )
            .await
            .unwrap();
            tokio::time::sleep(Duration::from_millis(500)).await;
            let path = format!("{dir}/phone-pot-{tab}.png");
            std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
            eprintln!("phone screenshot written to {path}");
        }
    }

    // Download by a tap; the checker passes the file.
    tap_id(&c, "download-gcode").await;
    let deadline = Instant::now() + Duration::from_secs(30);
    let file = loop {
        let done = std::fs::read_dir(&downloads)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| p.extension().is_some_and(|x| x == "gcode"));
        if let Some(p) = done {
            break p;
        }
        assert!(Instant::now() < deadline, "no G-code downloaded by a tap");
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    assert_eq!(file.file_name().unwrap(), "new pot.gcode");
    let text = std::fs::read_to_string(&file).unwrap();
    let printer = js(&c, "return window.sweepclay.design.printer").await;
    let printer = sweepclay_core::Printer::preset(printer.as_str().unwrap()).unwrap();
    let report = sweepclay_check::check(&text, &sweepclay_plan::printer_check(&printer));
    assert!(report.printable, "{:?}", report.failures);
    no_page_errors_and_close(c).await;
}

/// Issue 29's state defects at desktop size, each checked: two tabs keep
/// their own designs and histories and the one is told of the other; a
/// print grown too tall is framed at once, outside the printer is violet
/// (not the red of a limit), the out-of-date note leaves the legend
/// readable; a round bed's diameter is set in the printer editor; an
/// example keeps the printer chosen; a plain vessel's worst bead is one a
/// change can improve, with the change.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn tabs_views_and_printers_keep_the_truth() {
    let Some(Session {
        tmp: _tmp,
        downloads,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };

    // Worst bead on the vase: not the spiral's start, with advice where
    // room is short.
    c.goto(&format!("{base}/?example=vase")).await.unwrap();
    close_guide(&c).await;

    wait_js(&c, PRINTABLE, "the vase").await;
    // The verdict may come before the preview's frame: the legend is
    // waited for.
    let legend = wait_js(
        &c,
        &format!("return {IDLE} && document.getElementById('legend').textContent.includes('least room') ? document.getElementById('legend').textContent : null"),
        "the vase's legend",
    )
    .await;
    let legend = legend.as_str().unwrap();
    assert!(
        !legend.contains("layer 0.0"),
        "the spiral's start marked: {legend}"
    );
    // A print that passes gets no advice: following it would change
    // nothing (issue 57, point 1: a straight cylinder was told to pull
    // its wall in by 0.5 mm at its foot).
    for example in ["vase", "cylinder"] {
        c.goto(&format!("{base}/?example={example}")).await.unwrap();
        wait_js(&c, PRINTABLE, example).await;
        let legend = wait_js(
            &c,
            &format!("return {IDLE} && document.getElementById('legend').textContent.includes('least room') ? document.getElementById('legend').textContent : null"),
            "the legend",
        )
        .await;
        let legend = legend.as_str().unwrap();
        assert!(
            !legend.contains("pull the wall") && !legend.contains("lean the wall"),
            "{example}: advice on a print that passes: {legend}"
        );
    }

    // Tab A edits; tab B opens the last saved design and changes it.
    c.goto(&format!("{base}/?example=t1")).await.unwrap();
    wait_js(&c, PRINTABLE, "t1 in tab A").await;
    set_value(&c, "p-overlap", "70").await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.params.overlap === 0.7"),
        "the edit in tab A",
    )
    .await;
    tokio::time::sleep(Duration::from_millis(500)).await;
    let a_steps = js(&c, "return window.sweepclay.history.length").await;
    let tab_a = c.window().await.unwrap();
    let tab_b = c.new_window(true).await.unwrap();
    c.switch_to_window(tab_b.handle).await.unwrap();
    c.goto(&base).await.unwrap();
    wait_js(&c, &format!("return {IDLE} && window.sweepclay.design && window.sweepclay.design.params?.overlap === 0.7"), "tab B starting from A's design").await;
    set_value(&c, "name", "from tab B").await;
    tokio::time::sleep(Duration::from_millis(600)).await;
    c.switch_to_window(tab_a.clone()).await.unwrap();
    wait_js(
        &c,
        "return document.getElementById('other-tab') !== null",
        "tab A told of tab B's design",
    )
    .await;
    assert_eq!(
        js(&c, "return window.sweepclay.design.name").await,
        json!("t1 wave ring")
    );
    // A reload keeps this tab's own design and history.
    c.goto(&base).await.unwrap();
    wait_js(
        &c,
        &format!("return window.sweepclay.design && {IDLE}"),
        "tab A reloaded",
    )
    .await;
    assert_eq!(
        js(&c, "return window.sweepclay.design.name").await,
        json!("t1 wave ring")
    );
    assert_eq!(
        js(&c, "return window.sweepclay.history.length").await,
        a_steps
    );

    // A print too tall for the printer: framed at once, violet outside.
    c.goto(&format!("{base}/?example=t1")).await.unwrap();
    wait_js(&c, PRINTABLE, "t1 again").await;
    click(&c, "new-pot").await;
    wait_js(
        &c,
        &format!("return {IDLE} && {}", &PRINTABLE[7..]),
        "a new pot",
    )
    .await;
    set_value(&c, "pot-height", "400").await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.profile_start.control_points.at(-1)[1] === 400 && document.getElementById('verdict').dataset.printable === 'false'"),
        "the pot too tall",
    )
    .await;
    assert_eq!(
        js(&c, "return window.sweepclay.view.inView()").await,
        json!(true),
        "the tall pot is off-screen"
    );
    let out = js(&c, "const b = [...document.querySelectorAll('#legend b')].find((b) => b.textContent.includes('outside the printer')); return b ? getComputedStyle(b).color : null").await;
    assert_eq!(
        out,
        json!("rgb(143, 69, 224)"),
        "outside the printer is not violet"
    );
    // A design that does not slice: the out-of-date note and the legend
    // are both readable.
    set_value(&c, "pot-height", "120").await;
    set_value(&c, "p-layer_height", "9").await;
    wait_js(
        &c,
        &format!("return {IDLE} && !document.getElementById('stale-note').hidden"),
        "the out-of-date note",
    )
    .await;
    let b = boxes(&c, "#stale-note, #legend").await;
    no_overlap("stale note and legend", &b);
    set_value(&c, "p-layer_height", "1.25").await;

    // The printer editor sets a round bed; an example keeps the printer.
    click(&c, "printer-edit").await;
    set_value(&c, "pr-dia", "250").await;
    click(&c, "pr-save").await;
    wait_js(
        &c,
        "return window.sweepclay.design.printer?.bed_diameter === 250",
        "the round bed",
    )
    .await;
    // A start code saying M83 while relative extrusion is off is refused
    // in the dialog, naming the switch; with the switch on it prints.
    click(&c, "printer-edit").await;
    set_value(&c, "pr-start", "G28\nM83 ; relative E\n").await;
    click(&c, "pr-save").await;
    let said = wait_js(
        &c,
        "return document.getElementById('pr-error').textContent || null",
        "the start code's contradiction",
    )
    .await;
    assert!(said.as_str().unwrap().contains("M83"), "{said}");
    set_checked(&c, "pr-rel").await;
    click(&c, "pr-save").await;
    wait_js(
        &c,
        &format!(
            "return window.sweepclay.design.printer?.relative_e === true && {IDLE} && {}",
            &PRINTABLE[7..]
        ),
        "the printer with relative E",
    )
    .await;
    // Its G-code keeps M83 (no M82 after the start code) and lifts the
    // nozzle 10 mm clear of the rim before the end code; the checker
    // passes it on that printer.
    let file = download_gcode(&c, &downloads, "no relative-E G-code was downloaded").await;
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.contains("M83"), "no M83");
    assert!(
        !text.lines().any(|l| l.starts_with("M82")),
        "an M82 cancels M83"
    );
    let body: Vec<&str> = text.lines().filter(|l| !l.starts_with(';')).collect();
    let last_e = body
        .iter()
        .rposition(|l| l.starts_with("G1") && l.contains(" E"))
        .unwrap();
    let lift = &body[last_e + 1..];
    assert!(
        lift.len() >= 3
            && lift[0].starts_with("G91")
            && lift[1].starts_with("G1 Z10 ")
            && lift[2].starts_with("G90"),
        "no lift after the last bead: {lift:?}"
    );
    let printer = js(&c, "return JSON.stringify(window.sweepclay.design.printer)").await;
    let printer: sweepclay_core::Printer = serde_json::from_str(printer.as_str().unwrap()).unwrap();
    let report = sweepclay_check::check(&text, &sweepclay_plan::printer_check(&printer));
    assert!(report.printable, "{:?}", report.failures);
    set_value(&c, "p-printer", "cerambot-mini").await;
    wait_js(
        &c,
        "return window.sweepclay.design.printer === 'cerambot-mini'",
        "the printer chosen",
    )
    .await;
    set_value(&c, "example", "t2").await;
    wait_js(
        &c,
        "return window.sweepclay.design.name !== 'new pot' && window.sweepclay.design.printer === 'cerambot-mini'",
        "the example on the printer chosen",
    )
    .await;
    no_page_errors_and_close(c).await;
}

/// Issue 31 in the modeler: a texture added from the Surface panel, its
/// depth set by its slider, a twist, the preview coloured by how much of
/// the texture is kept, and the downloaded G-code carries the texture
/// (its wall moves in and out) and passes the independent checker.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_texture_and_a_twist_are_added_and_their_gcode_prints() {
    let Some(Session {
        tmp: _tmp,
        downloads,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    c.goto(&format!("{base}/?example=vase")).await.unwrap();
    close_guide(&c).await;
    wait_js(&c, PRINTABLE, "the vase").await;
    set_value(&c, "tex-add", "ripple").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.texture?.[0]?.kind === 'ripple' && document.getElementById('tex-amplitude-0') !== null && {}",
            &PRINTABLE[7..]
        ),
        "the ripple added",
    )
    .await;
    set_value(&c, "tex-amplitude-0", "1.5").await;
    set_value(&c, "twist", "20").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.texture[0].amplitude === 1.5 && window.sweepclay.design.twist_deg === 20 && {}",
            &PRINTABLE[7..]
        ),
        "the ripple 1.5 mm deep, twisted 20°",
    )
    .await;
    // Where the clay would not hold it, the page says so.
    let said = js(
        &c,
        "return document.getElementById('corrections').textContent",
    )
    .await;
    assert!(
        said.as_str().unwrap().contains("texture ripple 1.5 mm"),
        "{said}"
    );
    set_value(&c, "colour-by", "texture").await;
    let legend = wait_js(
        &c,
        "const t = document.getElementById('legend').textContent; return t.includes('kept whole') ? t : null",
        "the texture legend",
    )
    .await;
    assert!(
        legend.as_str().unwrap().contains("texture reduced"),
        "{legend}"
    );
    // One truth: the share of the wall Corrections says was reduced is the
    // share the "texture kept" colouring shows reduced (its wall beads).
    let truth = js(
        &c,
        "const d = window.sweepclay.sliced; let n = 0;
         for (let i = 1; i < d.surface.columns.length; i += 2) n += d.surface.columns[i];
         let wall = 0, low = 0;
         d.path.order.forEach((s, i) => { if (s < n) { wall++; if (d.path.texture_kept[i] < 0.99) low++; } });
         return [document.getElementById('corrections').textContent, low / wall]",
    )
    .await;
    let said = truth[0].as_str().unwrap();
    let told: f64 = said
        .split("reduced on ")
        .skip(1)
        .map(|t| t.split(" %").next().unwrap().parse::<f64>().unwrap())
        .sum();
    let shown = 100.0 * truth[1].as_f64().unwrap();
    assert!(
        told > 0.0 && (told - shown).abs() <= 2.0 + 0.25 * shown,
        "Corrections says {told:.1} % reduced, the colouring shows {shown:.1} %: {said}"
    );
    if let Ok(path) = std::env::var("SWEEPCLAY_TEXTURE_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    download_printable(&c, &downloads, "no textured G-code was downloaded").await;
    // The ripple is in the file: the wall's distance from the axis at one
    // angle goes in and out with height, many times over.
    let design = js(&c, "return JSON.stringify(window.sweepclay.design)").await;
    let d = sweepclay_core::Design::from_json(design.as_str().unwrap()).unwrap();
    let s = sweepclay_core::slice(&d).unwrap();
    let kept = &s.corrected.kept;
    assert!(
        kept.iter().filter(|&&k| k > 0.99).count() > kept.len() / 2,
        "the ripple is mostly kept whole"
    );
    no_page_errors_and_close(c).await;
}

/// Opens the vase, then New pot, and waits for the new pot's verdict:
/// printable, with one profile.
async fn new_pot_from_the_vase(c: &Client, base: &str) {
    c.goto(&format!("{base}/?example=vase")).await.unwrap();
    close_guide(c).await;
    wait_js(c, PRINTABLE, "the vase").await;
    click(c, "new-pot").await;
    wait_js(
        c,
        &format!(
            "return {IDLE} && !window.sweepclay.design.profile_end && {}",
            &PRINTABLE[7..]
        ),
        "a new pot",
    )
    .await;
}

/// The pot panel's rim control (docs/MODELER.md): a new pot's rim raised
/// 30 mm at the back becomes the design's `rim`, prints (the raised part as
/// partial layers, which the statistics say), and the G-code downloaded
/// stands 30 mm taller at the back than at the front.
#[tokio::test(flavor = "multi_thread")]
async fn a_pot_gets_a_raised_back_from_the_rim_control() {
    let Some(Session {
        tmp: _tmp,
        downloads,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    new_pot_from_the_vase(&c, &base).await;
    // Only a shape's own fields show.
    assert_eq!(
        js(&c, "return ['rim-rise-l', 'rim-peaks-l', 'rim-width-l'].map((id) => document.getElementById(id).hidden)").await,
        json!([true, true, true])
    );
    set_value(&c, "rim-shape", "raised").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.rim?.shape === 'raised' && {}",
            &PRINTABLE[7..]
        ),
        "the raised rim",
    )
    .await;
    assert_eq!(
        js(&c, "return ['rim-rise-l', 'rim-peaks-l', 'rim-width-l'].map((id) => document.getElementById(id).hidden)").await,
        json!([false, true, false])
    );
    // A value out of its range is refused beside the field, never changed.
    set_value(&c, "rim-width", "500").await;
    let said = wait_js(
        &c,
        "return document.getElementById('pot-error').textContent || null",
        "the width refused",
    )
    .await;
    assert!(said.as_str().unwrap().contains("from 1 to 360"), "{said}");
    assert_eq!(
        js(&c, "return window.sweepclay.design.rim.width_deg").await,
        json!(120)
    );
    set_value(&c, "rim-rise", "30").await;
    let stats = wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.rim.rise === 30 && {} && document.getElementById('stats').textContent.includes('raised rim') ? document.getElementById('stats').textContent : null",
            &PRINTABLE[7..]
        ),
        "the rim 30 mm higher at the back, printable",
    )
    .await;
    assert!(
        stats.as_str().unwrap().contains("partial layers"),
        "{stats}"
    );
    if let Ok(path) = std::env::var("SWEEPCLAY_RIM_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    let (text, printer) =
        download_printable(&c, &downloads, "no G-code of the raised rim was downloaded").await;
    // The highest clay at the back (+y) and at the front (−y).
    let (mut back, mut front) = (0.0f64, 0.0f64);
    let mut z = 0.0;
    for line in text.lines().filter(|l| l.starts_with("G1 ")) {
        let word = |c: char| {
            line.split_whitespace()
                .find(|w| w.starts_with(c))
                .and_then(|w| w[1..].parse::<f64>().ok())
        };
        z = word('Z').unwrap_or(z);
        if let Some(y) = word('Y') {
            let y = y - printer.origin[1];
            if y > 20.0 {
                back = back.max(z);
            } else if y < -20.0 {
                front = front.max(z);
            }
        }
    }
    assert!(
        (back - front - 30.0).abs() < 1.5,
        "back {back}, front {front}"
    );
    no_page_errors_and_close(c).await;
}

/// The wavy rim (docs/MODELER.md): picked on a new pot it prints as it
/// comes (three crests of 5 mm); raised to 20 mm the spiral cannot climb
/// and fall between the crests, and the verdict's most rise shows beside
/// the field; taking it prints.
#[tokio::test(flavor = "multi_thread")]
async fn a_wavy_rim_prints_as_it_comes_and_offers_the_most_that_prints() {
    let Some(Session {
        tmp: _tmp,
        downloads: _downloads,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    new_pot_from_the_vase(&c, &base).await;
    set_value(&c, "rim-shape", "wave").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.rim?.shape === 'wave' && {}",
            &PRINTABLE[7..]
        ),
        "the wavy rim as it comes, printable",
    )
    .await;
    assert_eq!(
        js(&c, "return [window.sweepclay.design.rim.rise, window.sweepclay.design.rim.peaks, document.getElementById('rim-most').hidden]").await,
        json!([5, 3, true])
    );
    set_value(&c, "rim-rise", "20").await;
    let most = wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.rim.rise === 20 && document.getElementById('verdict').dataset.printable === 'false' && !document.getElementById('rim-most').hidden ? Number(document.getElementById('rim-most-mm').textContent) : null"
        ),
        "the 20 mm wave refused, with the most that prints",
    )
    .await;
    let most = most.as_f64().unwrap();
    assert!((5.0..20.0).contains(&most), "{most}");
    let verdict = js(&c, "return document.getElementById('verdict').textContent").await;
    assert!(
        verdict
            .as_str()
            .unwrap()
            .contains(&format!("at most {most:.1} mm of rise")),
        "{verdict}"
    );
    if let Ok(dir) = std::env::var("SWEEPCLAY_SCREENSHOTS") {
        std::fs::write(
            format!("{dir}/wavy-most.png"),
            c.screenshot().await.unwrap(),
        )
        .unwrap();
        c.set_window_size(390, 844).await.unwrap();
        let _ = c
            .execute(
                "document.getElementById('rim-most').scrollIntoView({block: 'center'})",
                vec![],
            )
            .await;
        std::fs::write(
            format!("{dir}/wavy-most-phone.png"),
            c.screenshot().await.unwrap(),
        )
        .unwrap();
        c.set_window_size(1440, 900).await.unwrap();
    }
    click(&c, "rim-most-use").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.rim.rise === {most} && {}",
            &PRINTABLE[7..]
        ),
        "the most rise taken, printable",
    )
    .await;
    assert_eq!(
        js(&c, "return document.getElementById('rim-most').hidden").await,
        json!(true)
    );
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_cold_open_is_a_pot_and_its_guide_starts_from_new_pot() {
    // A potter's first minute: the page opens on a pot typed as widths at
    // heights, the guide's first step is New pot, and the menu offers the
    // shapes potters make before the paper's test pieces; each prints.
    let Some(Session {
        tmp: _tmp,
        downloads: _,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    c.goto(&base).await.unwrap();
    let first = wait_js(
        &c,
        "const g = document.getElementById('guide'); return g.open && g.querySelector('li').textContent",
        "the guide on a first visit",
    )
    .await;
    assert!(
        first.as_str().unwrap().starts_with("Press New pot"),
        "the guide's first step: {first}"
    );
    if let Ok(path) = std::env::var("SWEEPCLAY_GUIDE_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    close_guide(&c).await;
    wait_js(
        &c,
        &format!("return {IDLE} && {}", &PRINTABLE[7..]),
        "the first slice",
    )
    .await;
    let opened = js(
        &c,
        "const d = window.sweepclay.design; return [d.name, !!d.profile_end, [0, 1, 2, 3].map(i => document.getElementById('pot-w' + i)?.value), document.getElementById('pot-rows').offsetParent !== null]",
    )
    .await;
    assert_eq!(
        opened,
        json!(["belly vase", false, ["70", "115", "60", "72"], true]),
        "the cold open"
    );
    if let Ok(path) = std::env::var("SWEEPCLAY_COLD_OPEN_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    let menu = js(
        &c,
        "return [...document.querySelectorAll('#example optgroup')].map(g => [g.label, [...g.children].map(o => o.value)])",
    )
    .await;
    let pots = [
        "belly-vase",
        "cylinder",
        "bowl",
        "tumbler",
        "planter",
        "bud-vase",
    ];
    assert_eq!(menu[0], json!(["Pots", pots]), "the menu: {menu}");
    assert_eq!(
        menu[1][1],
        json!(["t1", "t2", "t3", "t4", "t5", "t6"]),
        "the menu: {menu}"
    );
    for pot in &pots[1..] {
        set_value(&c, "example", pot).await;
        wait_js(
            &c,
            &format!(
                "return {IDLE} && window.sweepclay.design.name.startsWith('{}') && {}",
                pot.replace('-', " "),
                &PRINTABLE[7..]
            ),
            &format!("{pot} printable"),
        )
        .await;
        assert_eq!(
            js(
                &c,
                "return document.getElementById('pot-rows').offsetParent !== null"
            )
            .await,
            json!(true),
            "{pot} opens in the widths table"
        );
    }
    // New pot, as the guide says: a pot sized to the printer, printable.
    click(&c, "new-pot").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.name === 'new pot' && {}",
            &PRINTABLE[7..]
        ),
        "the new pot printable",
    )
    .await;
    if let Ok(path) = std::env::var("SWEEPCLAY_NEW_POT_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_vessels_surface_is_closed_round_its_loop_and_its_sliders_fit() {
    // The solid render of a vessel had a slit where the loop's last
    // transition curve meets its first (a white seam); the texture
    // sliders' panel was wider than the side panel, their values pushed
    // out of sight.
    let Some(Session {
        tmp: _tmp,
        downloads: _,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    for (example, vessel) in [("ripple-vase", true), ("belly-vase", true), ("t1", false)] {
        c.goto(&format!("{base}/?example={example}&path=0"))
            .await
            .unwrap();
        if example == "ripple-vase" {
            close_guide(&c).await;
        }
        wait_js(
            &c,
            &format!(
                "return {IDLE} && window.sweepclay.design.name && {}",
                &PRINTABLE[7..]
            ),
            example,
        )
        .await;
        // An edge between two samples of one transition curve that only
        // one triangle has is a slit in the surface; a wall has them at
        // its two ends, a vessel none.
        let slits = js(
            &c,
            "const s = window.sweepclay.sliced.surface; const T = s.triangles, cols = s.columns;
             const curve = new Int32Array(s.positions.length / 3).fill(-1);
             for (let c = 0; 2 * c < cols.length; c++) for (let k = 0; k < cols[2 * c + 1]; k++) curve[cols[2 * c] + k] = c;
             const seen = new Map();
             for (let t = 0; t < T.length; t += 3) for (const [a, b] of [[T[t], T[t + 1]], [T[t + 1], T[t + 2]], [T[t + 2], T[t]]]) {
               const k = a < b ? a * 4294967296 + b : b * 4294967296 + a;
               seen.set(k, (seen.get(k) || 0) + 1);
             }
             let n = 0;
             for (const [k, count] of seen) {
               const a = Math.floor(k / 4294967296), b = k % 4294967296;
               if (count === 1 && curve[a] === curve[b] && curve[a] >= 0) n++;
             }
             return [n, cols.length / 2]",
        )
        .await;
        let n = slits[0].as_u64().unwrap();
        if vessel {
            assert_eq!(n, 0, "{example}: {n} slit edges in its surface");
        } else {
            assert!(n > 0, "{example}: a wall's two ends are open");
        }
    }
    // The ripple's sliders (the twist; depth, period, fades and where
    // the wave starts), on a desktop and on a phone's Settings tab.
    c.goto(&format!("{base}/?example=ripple-vase"))
        .await
        .unwrap();
    wait_js(
        &c,
        &format!("return {IDLE} && {}", &PRINTABLE[7..]),
        "the ripple",
    )
    .await;
    let fits = "const s = document.getElementById('side'); const r = s.getBoundingClientRect();
        const outs = [...document.querySelectorAll('#surface-panel output')].map(o => o.getBoundingClientRect());
        return [s.scrollWidth - s.clientWidth, outs.length, outs.every(o => o.right <= r.left + s.clientWidth + 0.5 && o.width > 0)]";
    let desk = js(&c, fits).await;
    assert_eq!(
        desk,
        json!([0, 6, true]),
        "desktop: overflow, outputs, all in sight"
    );
    c.set_window_size(390, 844).await.unwrap();
    c.execute(
        "document.querySelector('#tabs button[data-tab=side]').click()",
        vec![],
    )
    .await
    .unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    let phone = js(
        &c,
        "const outs = [...document.querySelectorAll('#surface-panel output')].map(o => o.getBoundingClientRect());
         return [document.documentElement.scrollWidth - window.innerWidth, outs.every(o => o.right <= window.innerWidth && o.width > 0)]",
    )
    .await;
    assert_eq!(phone, json!([0, true]), "phone: overflow, all in sight");
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_fingers_pan_the_3d_view_on_a_phone_and_the_hint_says_so() {
    // On a touch screen there is no right button and no shift key: two
    // fingers moving together pan the 3D view, apart they zoom.
    let Some(Session {
        tmp: _tmp,
        downloads: _,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    c.set_window_size(390, 844).await.unwrap();
    c.goto(&format!("{base}/?example=vase")).await.unwrap();
    close_guide(&c).await;
    wait_js(
        &c,
        &format!("return {IDLE} && {}", &PRINTABLE[7..]),
        "the vase",
    )
    .await;
    c.execute(
        "document.querySelector('#tabs button[data-tab=preview]').click()",
        vec![],
    )
    .await
    .unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    let hint = js(
        &c,
        "return document.getElementById('view-hint').textContent",
    )
    .await;
    assert!(
        hint.as_str().unwrap().contains("two fingers: pan"),
        "{hint}"
    );
    let mid = js(
        &c,
        "const r = document.getElementById('view3d').getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2]",
    )
    .await;
    let (x, y) = (mid[0].as_f64().unwrap(), mid[1].as_f64().unwrap());
    let view =
        "const v = window.sweepclay.view; return [v.target[0], v.target[1], v.target[2], v.dist]";
    // Each finger from its start by `by` (px) in 10 moves.
    let gesture = |starts: [(f64, f64); 2], by: [(f64, f64); 2]| {
        let finger = |name: &str, from: (f64, f64), by: (f64, f64)| {
            let mut t = TouchActions::new(name.into())
                .then(PointerAction::MoveTo {
                    duration: None,
                    x: from.0.round(),
                    y: from.1.round(),
                })
                .then(PointerAction::Down {
                    button: MOUSE_BUTTON_LEFT,
                });
            for k in 1..=10 {
                let f = k as f64 / 10.0;
                t = t.then(PointerAction::MoveTo {
                    duration: Some(Duration::from_millis(16)),
                    x: (from.0 + by.0 * f).round(),
                    y: (from.1 + by.1 * f).round(),
                });
            }
            t.then(PointerAction::Up {
                button: MOUSE_BUTTON_LEFT,
            })
        };
        fantoccini::actions::Actions::from(vec![
            finger("one", starts[0], by[0]),
            finger("two", starts[1], by[1]),
        ])
    };
    let num = |v: &serde_json::Value, i: usize| v[i].as_f64().unwrap();
    let before = js(&c, view).await;
    // Together 80 px to the right: the view pans, its distance stays.
    c.perform_actions(gesture(
        [(x - 40.0, y), (x + 40.0, y)],
        [(80.0, 0.0), (80.0, 0.0)],
    ))
    .await
    .unwrap();
    let panned = js(&c, view).await;
    let moved = (0..3)
        .map(|i| (num(&panned, i) - num(&before, i)).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        moved > 5.0,
        "two fingers moved the target {moved:.1} mm: {before} → {panned}"
    );
    assert!(
        (num(&panned, 3) / num(&before, 3) - 1.0).abs() < 0.05,
        "two fingers together zoomed: {before} → {panned}"
    );
    // Apart: the view zooms in, and the target stays.
    c.perform_actions(gesture(
        [(x - 30.0, y), (x + 30.0, y)],
        [(-40.0, 0.0), (40.0, 0.0)],
    ))
    .await
    .unwrap();
    let pinched = js(&c, view).await;
    assert!(
        num(&pinched, 3) < 0.8 * num(&panned, 3),
        "a pinch: {panned} → {pinched}"
    );
    let moved = (0..3)
        .map(|i| (num(&pinched, i) - num(&panned, i)).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(
        moved < 0.25 * num(&pinched, 3),
        "a pinch panned {moved:.1} mm: {panned} → {pinched}"
    );
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_point_bar_stands_under_the_selected_points_editor_on_a_phone() {
    // On a phone the editors stand one under another, 320 px each: the
    // bar to type a point's coordinates was below all four, up to 1,000 px
    // from the point tapped.
    let Some(Session {
        tmp: _tmp,
        downloads: _,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    c.set_window_size(390, 844).await.unwrap();
    open_first_slice(&c, &base).await;
    for (editor, canvas) in [(0, "ed-start"), (2, "ed-traj"), (1, "ed-end")] {
        js(
            &c,
            &format!(
                "document.getElementById('{canvas}').scrollIntoView({{block: 'center'}}); return 0"
            ),
        )
        .await;
        tokio::time::sleep(Duration::from_millis(200)).await;
        let p = point_at(&c, editor, "1").await;
        tap(&c, p).await;
        let gap = wait_js(
            &c,
            &format!(
                "const a = document.getElementById('{canvas}').getBoundingClientRect();
                 const b = document.getElementById('point-bar').getBoundingClientRect();
                 return document.getElementById('pb-x').disabled ? null : [b.top - a.bottom, b.height]"
            ),
            "the point selected",
        )
        .await;
        let below = gap[0].as_f64().unwrap();
        assert!(
            (0.0..=60.0).contains(&below),
            "{canvas}: the point bar is {below:.0} px below the editor"
        );
    }
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_3d_views_drawn_profiles_are_the_librarys() {
    // While the pointer moves, the 3D view draws the edited profiles
    // itself (`curves3d.js`): they must stand where the library's
    // transition curves do, offset from o or across the path, open or
    // round a loop. Each of the library's samples on the start profile's
    // curve (and the end profile's, on an open wall) lies on the drawn
    // polyline within 0.05 mm (measured: 0.019 at most). The page once
    // took a loop's frame at its seam from one side: 0.19 mm off on the
    // vase across its path.
    let Some(Session {
        tmp: _tmp,
        downloads: _,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    c.goto(&format!("{base}/?example=t1")).await.unwrap();
    close_guide(&c).await;
    let normal = |name: &str| {
        let mut v: Value =
            serde_json::from_str(sweepclay_core::examples::example(name).unwrap()).unwrap();
        v["trajectory"]["offset"] = "normal".into();
        v
    };
    let designs: Vec<(&str, Value)> = vec![
        (
            "t1",
            serde_json::from_str(sweepclay_core::examples::example("t1").unwrap()).unwrap(),
        ),
        (
            "t5",
            serde_json::from_str(sweepclay_core::examples::example("t5").unwrap()).unwrap(),
        ),
        ("t1 across the path", normal("t1")),
        (
            "vase",
            serde_json::from_str(sweepclay_core::examples::example("vase").unwrap()).unwrap(),
        ),
        ("vase across the path", normal("vase")),
        (
            "flower",
            serde_json::from_str(sweepclay_core::examples::example("flower").unwrap()).unwrap(),
        ),
        (
            "belly vase",
            serde_json::from_str(sweepclay_core::examples::example("belly-vase").unwrap()).unwrap(),
        ),
    ];
    for (name, v) in designs {
        let drawn = c
            .execute_async(
                "const [d, done] = arguments; import('/assets/curves3d.js').then((m) => done(m.profileLines(d)));",
                vec![v.clone()],
            )
            .await
            .unwrap();
        let lines: Vec<Vec<[f64; 3]>> = serde_json::from_value(drawn).unwrap();
        let d = sweepclay_core::Design::from_json(&v.to_string()).unwrap();
        let s = sweepclay_core::surface::sample_surface(&d).unwrap();
        let closed = d.trajectory.closed;
        let mut asked = vec![(0, &lines[0])];
        if !closed {
            asked.push((s.columns.len() - 1, &lines[1]));
        }
        for (col, line) in asked {
            let mut worst: f64 = 0.0;
            for si in s.columns[col].samples() {
                let q = s.position(col, si);
                let d = line
                    .windows(2)
                    .map(|w| segment_distance(q, w[0], w[1]))
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(d);
            }
            assert!(
                worst < 0.05,
                "{name}: column {col}'s samples lie up to {worst:.2} mm from the drawn profile"
            );
        }
    }
    no_page_errors_and_close(c).await;
}

/// The distance from `q` to the segment `a`–`b` (3D).
fn segment_distance(q: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let aq = [q[0] - a[0], q[1] - a[1], q[2] - a[2]];
    let l2 = ab.iter().map(|v| v * v).sum::<f64>();
    let t = if l2 > 0.0 {
        (ab.iter().zip(aq).map(|(u, v)| u * v).sum::<f64>() / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|i| (aq[i] - t * ab[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_drag_slices_only_when_the_pointer_rests_or_lets_go() {
    // While the pointer moves, the page draws the edited curves and does
    // not slice; the pointer resting 100 ms mid-drag slices once, the
    // release once more (docs/MODELER.md, "The curve follows the finger").
    let Some(Session {
        tmp: _tmp,
        downloads: _,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    open_first_slice(&c, &base).await;
    // Under load the browser may hand the page two moves 100 ms apart or
    // more: a rest. The test counts them, and allows a slice for each.
    js(
        &c,
        "window.moves = []; document.addEventListener('pointermove', () => window.moves.push(performance.now()), true); return 0",
    )
    .await;
    let rests = "const m = window.moves.splice(0); let n = 0; for (let i = 1; i < m.length; i++) if (m[i] - m[i - 1] >= 100) n++; return n";
    let sent0 = js(&c, "return window.sweepclay.sent")
        .await
        .as_u64()
        .unwrap();
    let top = point_at(&c, 1, "ed.points.length - 1").await;
    let moves = |m: MouseActions, from: f64, to: f64| {
        (1..=30).fold(m, |m, k| {
            m.then(PointerAction::MoveTo {
                duration: Some(Duration::from_millis(16)),
                x: top.0.round(),
                y: (top.1 + from + (to - from) * k as f64 / 30.0).round(),
            })
        })
    };
    // Thirty moves 16 ms apart, then a rest with the button still down.
    let first = moves(
        MouseActions::new("mouse".into())
            .then(PointerAction::MoveTo {
                duration: None,
                x: top.0.round(),
                y: top.1.round(),
            })
            .then(PointerAction::Down {
                button: MOUSE_BUTTON_LEFT,
            }),
        0.0,
        -15.0,
    );
    c.perform_actions(first).await.unwrap();
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.sent > {sent0}"),
        "the slice of the rested drag",
    )
    .await;
    let rested = js(&c, "return window.sweepclay.sent")
        .await
        .as_u64()
        .unwrap();
    let rests1 = js(&c, rests).await.as_u64().unwrap();
    let rest_trip = js(&c, "return window.sweepclay.roundTrips.at(-1).rest")
        .await
        .as_bool();
    // Thirty more moves and the release.
    let second = moves(MouseActions::new("mouse".into()), -15.0, -30.0).then(PointerAction::Up {
        button: MOUSE_BUTTON_LEFT,
    });
    c.perform_actions(second).await.unwrap();
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.sent > {rested}"),
        "the slice of the released drag",
    )
    .await;
    let end = js(
        &c,
        "const s = window.sweepclay; return [s.sent, s.roundTrips.at(-1).rest, document.getElementById('preview').classList.contains('settling')]",
    )
    .await;
    let rests2 = js(&c, rests).await.as_u64().unwrap();
    // A slice sent while the moves came 16 ms apart would show here: one
    // for the rest, one for each gap the browser made a rest.
    assert!(
        rested > sent0 && rested <= sent0 + 1 + rests1,
        "{} slices for one rest and {rests1} gaps of 100 ms or more between moves",
        rested - sent0
    );
    assert_eq!(rest_trip, Some(true), "the rested slice is marked so");
    let end_sent = end[0].as_u64().unwrap();
    assert!(
        end_sent > rested && end_sent <= rested + 1 + rests2,
        "{} slices for the release and {rests2} gaps of 100 ms or more between moves",
        end_sent - rested
    );
    assert_eq!(
        end[1].as_bool(),
        Some(false),
        "the release's slice is not a rest's"
    );
    assert_eq!(
        end[2].as_bool(),
        Some(false),
        "the preview is no longer greyed"
    );
    wait_js(&c, PRINTABLE, "the verdict after the drag").await;
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_drag_on_a_busy_machine_is_not_taken_for_rests() {
    // A busy machine hands the page a drag's moves 100 ms and more apart
    // (docs/MODELER.md, "Speed budget"). A rest is a pause longer than the
    // moves' own gaps: twelve moves 180 ms apart slice about once (the
    // first gap, before any gap is known), where a fixed 100 ms sliced at
    // nearly every one; a second's rest still slices.
    let Some(Session {
        tmp: _tmp,
        downloads: _,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    open_first_slice(&c, &base).await;
    let sent = || async {
        js(&c, "return window.sweepclay.sent")
            .await
            .as_u64()
            .unwrap()
    };
    let sent0 = sent().await;
    let top = point_at(&c, 1, "ed.points.length - 1").await;
    let mut m = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: top.0.round(),
            y: top.1.round(),
        })
        .then(PointerAction::Down {
            button: MOUSE_BUTTON_LEFT,
        });
    for k in 1..=12 {
        m = m
            .then(PointerAction::Pause {
                duration: Duration::from_millis(180),
            })
            .then(PointerAction::MoveTo {
                duration: None,
                x: top.0.round(),
                y: (top.1 - 2.0 * k as f64).round(),
            });
    }
    c.perform_actions(m).await.unwrap();
    // At most once, and twice more where the machine, busy besides,
    // hands over one of the moves late enough to be a rest (a CI run
    // beside two other jobs saw 2): the fixed rule sent 11.
    let slow = sent().await - sent0;
    assert!(
        slow <= 3,
        "{slow} slices sent while the moves came 180 ms apart"
    );
    // A second's rest with the button down is a rest.
    tokio::time::sleep(Duration::from_millis(1500)).await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.sent > {}", sent0 + slow),
        "the slice of the rested drag",
    )
    .await;
    c.perform_actions(MouseActions::new("mouse".into()).then(PointerAction::Up {
        button: MOUSE_BUTTON_LEFT,
    }))
    .await
    .unwrap();
    wait_js(&c, PRINTABLE, "the verdict after the drag").await;
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_page_previews_the_path_it_downloads_point_for_point() {
    // A pot on a foot 150 mm wide, whose first G-code fails the check:
    // the plan tightens its corrections, and the preview must show the
    // path of the last round, the one the download prints. Opened from a
    // file and then edited (a twist), as a potter would.
    let Some(Session {
        tmp,
        downloads,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    c.goto(&base).await.unwrap();
    close_guide(&c).await;
    let file = tmp.path().join("foot-pot.json");
    std::fs::write(
        &file,
        include_str!("../../sweepclay-plan/tests/foot-pot.json"),
    )
    .unwrap();
    choose_file(&c, "open-file", &file).await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.name === 'new pot on a wide foot' && {}",
            &PRINTABLE[7..]
        ),
        "the foot pot, printable",
    )
    .await;
    set_value(&c, "twist", "20").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.twist_deg === 20 && {}",
            &PRINTABLE[7..]
        ),
        "the foot pot twisted 20°, printable",
    )
    .await;
    // What the 3D view draws besides its colours is named in the legend.
    let legend = js(&c, "return document.getElementById('legend').textContent").await;
    let legend = legend.as_str().unwrap();
    assert!(
        legend.contains("rim and top-edge beads")
            && legend.contains("surface moved by a correction"),
        "{legend}"
    );
    let corrections = js(
        &c,
        "return document.getElementById('corrections').textContent",
    )
    .await;
    assert!(
        corrections.as_str().unwrap().contains("correction loop"),
        "{corrections}"
    );
    let shown = js(
        &c,
        "const d = window.sweepclay.sliced;
         return Array.from(d.path.order).flatMap((s) => Array.from(d.surface.positions.subarray(3 * s, 3 * s + 3)));",
    )
    .await;
    let shown: Vec<f64> = shown
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let (text, printer) =
        download_printable(&c, &downloads, "no G-code of the foot pot was downloaded").await;
    // Every move's end in the file, in order, in the design's frame.
    let mut at = [0.0f64; 3];
    let mut moves = Vec::new();
    for line in text
        .lines()
        .filter(|l| l.starts_with("G1 ") || l.starts_with("G0 "))
    {
        for w in line.split_whitespace() {
            match (w.as_bytes()[0], w[1..].parse::<f64>()) {
                (b'X', Ok(x)) => at[0] = x - printer.origin[0],
                (b'Y', Ok(y)) => at[1] = y - printer.origin[1],
                (b'Z', Ok(z)) => at[2] = z,
                _ => {}
            }
        }
        moves.push(at);
    }
    let pts: Vec<[f64; 3]> = shown.chunks(3).map(|p| [p[0], p[1], p[2]]).collect();
    let off = |p: &[f64; 3], m: &[f64; 3]| (0..3).map(|a| (p[a] - m[a]).abs()).fold(0.0, f64::max);
    let first = moves
        .iter()
        .position(|m| off(&pts[0], m) < 0.006)
        .expect("the preview's first point among the G-code's moves");
    let tail = &moves[first..];
    assert!(
        tail.len() >= pts.len(),
        "{} moves for {} points",
        tail.len(),
        pts.len()
    );
    let worst = pts
        .iter()
        .zip(tail)
        .map(|(p, m)| off(p, m))
        .fold(0.0, f64::max);
    assert!(
        worst < 0.006,
        "the preview and the G-code differ by {worst} mm"
    );
    // The page draws the curves with its own B-splines (bspline.js): the
    // same curves as the library's, on clamped polygons of 2 to 9 points
    // and closed loops of 3 to 9.
    let polygons: Vec<Vec<[f64; 2]>> = (2..=9)
        .map(|n| {
            (0..n)
                .map(|i| {
                    let a = i as f64 * 2.4;
                    [
                        40.0 * a.cos() + 3.0 * i as f64,
                        25.0 * a.sin() - 7.0 * i as f64,
                    ]
                })
                .collect()
        })
        .collect();
    let page = c
        .execute_async(
            "const [polys, done] = arguments;
             import('/assets/bspline.js').then((b) => done({
               open: polys.map((p) => [0, 0.13, 0.5, 0.77, 1].map((t) => b.evalAt(p, t))),
               closed: polys.filter((p) => p.length >= 3).map((p) => b.samplePeriodic(p, 7)),
             }));",
            vec![json!(polygons)],
        )
        .await
        .unwrap();
    let xy = |v: &Value| [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()];
    let near = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) < 1e-9;
    for (k, poly) in polygons.iter().enumerate() {
        let curve = sweepclay_core::bspline::BSpline::clamped(poly.clone()).unwrap();
        for (j, t) in [0.0, 0.13, 0.5, 0.77, 1.0].into_iter().enumerate() {
            let (js_at, rust_at) = (xy(&page["open"][k][j]), curve.eval(t));
            assert!(
                near(js_at, rust_at),
                "{} points, t {t}: page {js_at:?}, library {rust_at:?}",
                poly.len()
            );
        }
    }
    for (k, poly) in polygons.iter().filter(|p| p.len() >= 3).enumerate() {
        let rust = sweepclay_core::curves::periodic_bspline(poly, 7);
        let page = page["closed"][k].as_array().unwrap();
        assert_eq!(page.len(), rust.len());
        assert!(
            page.iter().zip(&rust).all(|(a, &b)| near(xy(a), b)),
            "loop of {}",
            poly.len()
        );
    }
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_mesh_opens_as_an_editable_design_and_downloads_its_gcode() {
    // The cup's own STL, as a potter would bring a pot from elsewhere.
    let Some(Session {
        tmp,
        downloads,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    let cup = sweepclay_core::Design::from_json(sweepclay_core::examples::example("cup").unwrap())
        .unwrap();
    let mut stl = Vec::new();
    sweepclay_core::mesh::write_stl(&sweepclay_core::slice(&cup).unwrap(), &mut stl).unwrap();
    let file = tmp.path().join("old-cup.stl");
    std::fs::write(&file, &stl).unwrap();
    c.goto(&base).await.unwrap();
    close_guide(&c).await;
    // The potter's printer stays: opening a mesh (which names none) used
    // to switch it to generic, centring the G-code on another bed.
    set_value(&c, "p-printer", "cerambot-mini").await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.printer === 'cerambot-mini'"),
        "the printer chosen",
    )
    .await;
    choose_file(&c, "open-file", &file).await;
    let note = wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.name === 'old-cup' && {} && document.querySelector('#status .note')?.textContent || null",
            &PRINTABLE[7..]
        ),
        "the mesh opened as a printable design",
    )
    .await;
    let note = note.as_str().unwrap().to_string();
    assert!(
        note.contains("now an editable design within")
            && note.contains("a wall with its thickness"),
        "{note}"
    );
    if let Ok(path) = std::env::var("SWEEPCLAY_MESH_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    // Editable: its profile is a curve the editors hold, its round loop
    // a closed curve of a few control points (it was the 360 points of
    // the fit's rays), and the widths table a row per profile point.
    assert_eq!(
        js(&c, "return window.sweepclay.design.trajectory.closed").await,
        json!(true)
    );
    let loop_points = js(
        &c,
        "return window.sweepclay.design.trajectory.control_points?.length ?? -1",
    )
    .await;
    let loop_points = loop_points.as_i64().unwrap();
    assert!((4..=16).contains(&loop_points), "{loop_points} loop points");
    let (rows, profile) = (
        js(
            &c,
            "return document.querySelectorAll('#pot-rows tbody tr').length",
        )
        .await,
        js(
            &c,
            "return window.sweepclay.design.profile_start.control_points.length",
        )
        .await,
    );
    let (rows, profile) = (rows.as_i64().unwrap(), profile.as_i64().unwrap());
    assert!(
        profile <= 12 && rows <= profile + 1,
        "{rows} rows, {profile} points"
    );
    let (text, _) =
        download_printable(&c, &downloads, "no G-code of the mesh was downloaded").await;
    assert!(text.contains("; design: old-cup"), "{}", &text[..300]);
    assert!(
        text.contains("; printer: cerambot-mini"),
        "{}",
        &text[..300]
    );
    // A mesh that is no sweep (twisted lobes with a spiral texture)
    // opens as the closest twisted sweep and a relief, prints as it is,
    // and the note says its twist and why it could not be made editable.
    let lobes = sweepclay_core::Design::from_json(
        sweepclay_core::examples::example("twisted-lobes").unwrap(),
    )
    .unwrap();
    let mut stl = Vec::new();
    sweepclay_core::mesh::write_stl(&sweepclay_core::slice(&lobes).unwrap(), &mut stl).unwrap();
    let file = tmp.path().join("lobes.stl");
    std::fs::write(&file, &stl).unwrap();
    // The lobes were drawn for the larger CERAMBOT Plus: the potter picks it.
    set_value(&c, "p-printer", "cerambot-plus").await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.printer === 'cerambot-plus'"),
        "the larger printer chosen",
    )
    .await;
    choose_file(&c, "open-file", &file).await;
    let note = wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.name === 'lobes' && {} && document.querySelector('#status .note')?.textContent || null",
            &PRINTABLE[7..]
        ),
        "the twisted mesh opened as a printable design",
    )
    .await;
    let note = note.as_str().unwrap().to_string();
    assert!(
        note.contains("printed as the mesh is")
            && note.contains("could not be made an editable sweep")
            && note.contains("twisted 3")
            && note.contains("10 spiral ribs"),
        "{note}"
    );
    let twist = js(&c, "return window.sweepclay.design.twist_deg").await;
    assert!((twist.as_f64().unwrap() - 36.0).abs() < 2.0, "{twist}");
    assert_eq!(
        js(&c, "return window.sweepclay.design.relief.u.length").await,
        json!(360)
    );
    if let Ok(path) = std::env::var("SWEEPCLAY_RELIEF_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    // Sized and turned as a potter wants it: half as large, a quarter
    // turn, still printable, its relief kept; a size out of range is
    // refused beside the field; undo brings it back.
    let size = js(&c, "return window.sweepclay.sliced.stats.size_mm").await;
    let size: Vec<f64> = serde_json::from_value(size).unwrap();
    set_value(&c, "tf-scale", "5000000").await;
    click(&c, "tf-apply").await;
    let said = wait_js(
        &c,
        "return document.getElementById('tf-error').textContent || null",
        "the size refused",
    )
    .await;
    assert!(said.as_str().unwrap().contains("from 1 to 10000"), "{said}");
    set_value(&c, "tf-scale", "50").await;
    set_value(&c, "tf-turn", "90").await;
    click(&c, "tf-apply").await;
    let half = wait_js(
        &c,
        &format!(
            "const s = window.sweepclay.sliced?.stats.size_mm; return {IDLE} && {} && s[2] < 0.6 * {} && s",
            &PRINTABLE[7..],
            size[2]
        ),
        "the design at half its size",
    )
    .await;
    let half: Vec<f64> = serde_json::from_value(half).unwrap();
    for (h, (a, w)) in half
        .iter()
        .zip([(size[1], 3.0), (size[0], 3.0), (size[2], 1.5)])
    {
        assert!((h - 0.5 * a).abs() < w, "{half:?} against {size:?}");
    }
    assert_eq!(
        js(&c, "return window.sweepclay.design.relief.u.length").await,
        json!(360)
    );
    assert_eq!(
        js(&c, "return document.getElementById('tf-error').textContent").await,
        json!("")
    );
    click(&c, "undo").await;
    wait_js(
        &c,
        &format!(
            "const s = window.sweepclay.sliced?.stats.size_mm; return {IDLE} && s[2] > 0.9 * {}",
            size[2]
        ),
        "the design back at its size",
    )
    .await;
    // A mesh with a hole is refused by name.
    let broken = tmp.path().join("broken.stl");
    std::fs::write(&broken, b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 10 0 0\nvertex 0 10 20\nendloop\nendfacet\nendsolid x\n").unwrap();
    choose_file(&c, "open-file", &broken).await;
    let said = error_text(&c, "the broken mesh refused").await;
    assert!(said.as_str().unwrap().contains("has a hole"), "{said}");
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn fields_take_what_is_typed_or_say_why_beside_it() {
    // Round 3's walk: presets whose own values failed the printer
    // dialog's steps could not be saved; "2.5" floor layers gave a serde
    // message; a pot 99999 mm tall blamed the point spacing.
    let Some(Session {
        tmp: _tmp,
        downloads: _downloads,
        driver: _driver,
        c,
        base,
    }) = Session::start().await
    else {
        return;
    };
    c.goto(&format!("{base}/?example=vase")).await.unwrap();
    close_guide(&c).await;
    wait_js(&c, PRINTABLE, "the vase").await;
    for preset in [
        "eazao-zero",
        "eazao-potter",
        "wasp-2040-clay",
        "vormvrij-lutum-4.6",
    ] {
        set_value(&c, "p-printer", preset).await;
        wait_js(
            &c,
            &format!("return {IDLE} && window.sweepclay.design.printer === '{preset}'"),
            "the preset chosen",
        )
        .await;
        open_printer_dialog(&c).await;
        click(&c, "pr-save").await;
        let saved = wait_js(
            &c,
            "return !document.getElementById('printer-dialog').open && window.sweepclay.design.printer.name || null",
            &format!("{preset} saved as the user's own"),
        )
        .await;
        assert_eq!(saved, json!(format!("my {preset}")));
    }
    // The point bar: a value typed for the start profile's point goes to
    // that point, though the end profile had one selected before and is
    // refreshed after it; "1,5" is 1.5; a height its neighbours forbid is
    // refused beside the field, not moved elsewhere.
    let end_before = js(
        &c,
        "return JSON.stringify(window.sweepclay.design.profile_end)",
    )
    .await;
    js(&c, "const e = window.sweepclay.editors[1]; e.selected = 1; e.told(); const s = window.sweepclay.editors[0]; s.selected = 1; s.told(); return 0").await;
    set_value(&c, "pb-x", "1,5").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.profile_start.control_points[1][0] === 1.5"
        ),
        "the start profile's point at x 1.5",
    )
    .await;
    assert_eq!(
        js(
            &c,
            "return JSON.stringify(window.sweepclay.design.profile_end)"
        )
        .await,
        end_before
    );
    js(
        &c,
        "const s = window.sweepclay.editors[0]; s.selected = 2; s.told(); return 0",
    )
    .await;
    let z2 = js(
        &c,
        "return window.sweepclay.design.profile_start.control_points[2][1]",
    )
    .await;
    set_value(&c, "pb-y", "5").await;
    let said = wait_js(
        &c,
        "return document.getElementById('pb-error').textContent || null",
        "a height between the neighbours' refused",
    )
    .await;
    assert!(
        said.as_str().unwrap().contains("the point cannot go there"),
        "{said}"
    );
    assert_eq!(
        js(
            &c,
            "return window.sweepclay.design.profile_start.control_points[2][1]"
        )
        .await,
        z2
    );
    click(&c, "new-pot").await;
    wait_js(
        &c,
        &format!("return {IDLE} && !window.sweepclay.design.profile_end"),
        "a new pot",
    )
    .await;
    set_value(&c, "p-floor_layers", "2.5").await;
    let said = error_text(&c, "2.5 floor layers refused").await;
    let said = said.as_str().unwrap();
    assert!(
        said.contains("not a whole number of layers from 0 (bottomless) to 20")
            && !said.contains("u32"),
        "{said}"
    );
    assert_eq!(
        js(
            &c,
            "return window.sweepclay.design.params.floor_layers ?? 2"
        )
        .await,
        json!(2)
    );
    // "Add a height" goes into the largest gap; any height typed there
    // takes its place among the rows, which stay sorted.
    // The table's heights: the rows the profile passes through.
    let rows_z = "return Array.from(document.querySelectorAll('#pot-rows tbody input[id^=pot-z]')).map((i) => parseFloat(i.value))";
    let before = js(&c, rows_z).await;
    click(&c, "pot-add").await;
    let n = before.as_array().unwrap().len();
    wait_js(
        &c,
        &format!(
            "return {IDLE} && document.querySelectorAll('#pot-rows tbody tr').length === {} || null",
            n + 1
        ),
        "a height added",
    )
    .await;
    wait_js(&c, &format!("return {IDLE}"), "the table refilled").await;
    let added = js(&c, rows_z).await;
    let added: Vec<f64> = added
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let i = (1..added.len())
        .find(|&i| {
            !before
                .as_array()
                .unwrap()
                .iter()
                .any(|b| b.as_f64() == Some(added[i]))
        })
        .expect("the new row");
    set_value(&c, &format!("pot-z{i}"), "10").await;
    let zs = wait_js(
        &c,
        "const z = Array.from(document.querySelectorAll('#pot-rows tbody input[id^=pot-z]')).map((i) => parseFloat(i.value)); return z.includes(10) ? z : null",
        "the new height at 10 mm",
    )
    .await;
    let zs: Vec<f64> = zs
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(zs.windows(2).all(|w| w[0] < w[1]), "{zs:?}");
    assert_eq!(zs[1], 10.0, "{zs:?}");
    // Typed changes re-frame the editors: the path at a 150 mm base, the
    // profile at 260 mm tall, each wholly in its view.
    let in_view = "return [0, 2].map((k) => { const e = window.sweepclay.editors[k]; return e.points.every((p) => { const [x, y] = e.toScreen(p); return x >= 0 && y >= 0 && x <= e.w && y <= e.h; }); })";
    set_value(&c, "pot-w0", "150").await;
    set_value(&c, "pot-height", "260").await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.profile_start.control_points.at(-1)[1] === 260"),
        "the pot 260 mm tall on a 150 mm base",
    )
    .await;
    assert_eq!(js(&c, in_view).await, json!([true, true]));
    if let Ok(path) = std::env::var("SWEEPCLAY_FIELDS_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    // Firing shrinkage, in the file format, is on the page: 10 % across
    // prints the pot 11.1 % larger, and the statistics say so.
    set_value(&c, "p-shrinkage_xy", "10").await;
    let said = wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.params.shrinkage_xy === 0.1 && document.querySelector('[data-stat=\"firing shrinkage\"]')?.textContent || null"),
        "the shrinkage in the statistics",
    )
    .await;
    assert!(
        said.as_str()
            .unwrap()
            .starts_with("printed 11.1 % larger across, 0.0 % taller"),
        "{said}"
    );
    set_value(&c, "p-shrinkage_xy", "0").await;
    set_value(&c, "pot-height", "99999").await;
    let said = wait_js(
        &c,
        "return document.getElementById('pot-error').textContent || null",
        "the height refused",
    )
    .await;
    assert!(
        said.as_str().unwrap().contains(
            "at most 2040 mm here, four times the 510 mm the my vormvrij-lutum-4.6 prints"
        ),
        "{said}"
    );
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_pot_is_sent_from_the_page_to_octoprint_and_printed() {
    let host_dir = tempfile::tempdir().unwrap();
    let Some(octo) = hosts::octoprint(&host_dir.path().join("octoprint")) else {
        return;
    };
    // The server keeps the key in this run's own keys file.
    std::env::set_var("SWEEPCLAY_CONFIG_DIR", host_dir.path().join("config"));
    let Some(Session {
        tmp,
        driver: _driver,
        c,
        base,
        ..
    }) = Session::start().await
    else {
        return;
    };
    // A small cup, 20 mm tall, on a CERAMBOT Mini.
    let mut d: Value =
        serde_json::from_str(sweepclay_core::examples::example("cup").unwrap()).unwrap();
    for k in ["profile_start", "profile_end"] {
        d[k]["control_points"] = json!([[0, 0], [0.5, 8], [2, 20]]);
    }
    d["name"] = "pot".into();
    let file = tmp.path().join("pot.json");
    std::fs::write(&file, d.to_string()).unwrap();
    c.goto(&base).await.unwrap();
    close_guide(&c).await;
    choose_file(&c, "open-file", &file).await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && window.sweepclay.design.name === 'pot' && {}",
            &PRINTABLE[7..]
        ),
        "the pot opened, printable",
    )
    .await;
    // No host yet: the button says so and opens the printer dialog.
    click(&c, "send-printer").await;
    wait_js(
        &c,
        "return document.getElementById('printer-dialog').open",
        "the printer dialog",
    )
    .await;
    let said = js(
        &c,
        "return document.getElementById('send-status').textContent",
    )
    .await;
    assert!(said.as_str().unwrap().contains("No print host"), "{said}");
    set_value(&c, "pr-host-kind", "octoprint").await;
    set_value(&c, "pr-host-url", &format!("{}/", octo.url)).await;
    set_value(&c, "pr-host-key", &octo.key).await;
    click(&c, "pr-save").await;
    wait_js(
        &c,
        &format!("return {IDLE} && window.sweepclay.design.printer.host?.kind === 'octoprint'"),
        "the printer with its host",
    )
    .await;
    // The key is on the server's machine, not in the design or the page's
    // storage.
    let stored = js(
        &c,
        "return JSON.stringify(window.sweepclay.design) + JSON.stringify(localStorage)",
    )
    .await;
    assert!(
        !stored.as_str().unwrap().contains(&octo.key),
        "the key is in the page"
    );
    let keys = host_dir.path().join("config").join("host-keys.json");
    let deadline = Instant::now() + Duration::from_secs(10);
    while !std::fs::read_to_string(&keys).is_ok_and(|k| k.contains(&octo.key)) {
        assert!(Instant::now() < deadline, "the key was not saved");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }

    // It asks first, saying what the print takes; "Not now" sends nothing.
    click(&c, "send-printer").await;
    let asked = wait_js(
        &c,
        "const d = document.getElementById('send-confirm'); return d.open && document.getElementById('send-what').textContent",
        "the question before printing",
    )
    .await;
    let asked = asked.as_str().unwrap();
    assert!(
        asked.contains("min and") && asked.contains("ml of clay"),
        "{asked}"
    );
    js(
        &c,
        "document.getElementById('send-confirm').close('cancel'); return 0",
    )
    .await;
    wait_js(
        &c,
        "return document.getElementById('send-status').textContent === 'not sent'",
        "not sent",
    )
    .await;
    click(&c, "send-printer").await;
    wait_js(
        &c,
        "return document.getElementById('send-confirm').open",
        "the question again",
    )
    .await;
    click(&c, "send-go").await;
    // The page follows the print to its end; it is paused and resumed
    // on the way (issue 59, point 3).
    let deadline = Instant::now() + Duration::from_secs(240);
    let mut shot = false;
    let mut paused = false;
    loop {
        let s = js(
            &c,
            "return document.getElementById('send-status').textContent",
        )
        .await;
        let s = s.as_str().unwrap_or("").to_string();
        assert!(!s.contains("Not sent") && !s.contains("lost"), "{s}");
        if s.starts_with("Printing") && !shot {
            shot = true;
            if let Ok(path) = std::env::var("SWEEPCLAY_SEND_SCREENSHOT") {
                std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
            }
        }
        if s.starts_with("Printing") && !paused {
            paused = true;
            click(&c, "job-pause").await;
            wait_js(
                &c,
                "return document.getElementById('send-status').textContent.endsWith('(Paused)') && !document.getElementById('job-resume').hidden",
                "the print paused",
            )
            .await;
            click(&c, "job-resume").await;
        }
        if s == "pot.gcode: done" {
            break;
        }
        assert!(Instant::now() < deadline, "the print did not end: {s}");
        tokio::time::sleep(Duration::from_millis(500)).await;
    }
    assert!(paused, "never seen printing");
    // What OctoPrint received is the checked file, every line of it.
    let sent = std::fs::read_to_string(octo.dir.join("uploads").join("pot.gcode")).unwrap();
    let report = sweepclay_check::check(
        &sent,
        &sweepclay_plan::printer_check(&sweepclay_core::Printer::preset("cerambot-mini").unwrap()),
    );
    assert!(report.printable, "{:?}", report.failures);
    hosts::assert_received_in_order(&octo, &sent);
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_printer_dialog_calibrates_e_from_measured_walls() {
    let Some(Session {
        downloads,
        driver: _driver,
        c,
        base,
        ..
    }) = Session::start().await
    else {
        return;
    };
    open_first_slice(&c, &base).await;
    open_printer_dialog(&c).await;
    js(
        &c,
        "document.getElementById('pr-cal').open = true; return null",
    )
    .await;
    let e0: f64 = js(
        &c,
        "return parseFloat(document.getElementById('pr-e').value)",
    )
    .await
    .as_f64()
    .unwrap();
    click(&c, "pr-cal-print").await;
    let deadline = Instant::now() + Duration::from_secs(30);
    let file = loop {
        let f = downloads.join("calibration.gcode");
        if f.exists() && std::fs::metadata(&f).unwrap().len() > 0 {
            break f;
        }
        assert!(
            Instant::now() < deadline,
            "no calibration print was downloaded"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    // It passes the independent check, as its own header reads it.
    let text = std::fs::read_to_string(&file).unwrap();
    let cfg = sweepclay_check::header::config_from_header(
        &text,
        &sweepclay_check::CheckConfig::default(),
    )
    .unwrap();
    assert!(sweepclay_check::check(&text, &cfg).printable);
    // Walls 10 % thick (the extruder lays 1.1 mm³ a mm³ written), one with
    // a decimal comma, as a calliper reads them.
    for (k, v) in ["3,30", "4.41", "5.49", "6.61"].iter().enumerate() {
        set_value(&c, &format!("pr-cal-{}", k + 1), v).await;
    }
    click(&c, "pr-cal-fit").await;
    let said = wait_js(
        &c,
        "const t = document.getElementById('pr-cal-result').textContent; return t.startsWith('E per mm') && t",
        "the fit",
    )
    .await;
    let e: f64 = js(
        &c,
        "return parseFloat(document.getElementById('pr-e').value)",
    )
    .await
    .as_f64()
    .unwrap();
    let truth = e0 / 1.1;
    assert!((e - truth).abs() / truth < 0.02, "{e} vs {truth}: {said}");
    // Compute again from the same walls: the same E (before, each Compute
    // took the field's E as the one printed with: 0.416 → 0.462 → 0.513).
    js(
        &c,
        "document.getElementById('pr-cal-result').textContent = ''",
    )
    .await;
    click(&c, "pr-cal-fit").await;
    wait_js(
        &c,
        "const t = document.getElementById('pr-cal-result').textContent; return t.startsWith('E per mm') && t",
        "the fit again",
    )
    .await;
    let again: f64 = js(
        &c,
        "return parseFloat(document.getElementById('pr-e').value)",
    )
    .await
    .as_f64()
    .unwrap();
    assert_eq!(again, e, "Compute is idempotent");
    // In words a potter reads: E to five digits, not 0.41575168807678786.
    let shown = js(&c, "return document.getElementById('pr-e').value").await;
    let digits = shown.as_str().unwrap().trim_start_matches("0.").len();
    assert!(digits <= 5, "{shown}");
    assert!(said.as_str().unwrap().len() < 160, "{said}");
    // A diameter typed for a wall names the band, not `measured[0]`.
    set_value(&c, "pr-cal-1", "80").await;
    click(&c, "pr-cal-fit").await;
    let bad = wait_js(
        &c,
        "const t = document.getElementById('pr-cal-result').textContent; return t.includes('not a wall thickness') && t",
        "the band refused",
    )
    .await;
    let bad = bad.as_str().unwrap();
    assert!(bad.starts_with("band 1 from the bottom: 80 mm"), "{bad}");
    assert!(!bad.contains('['), "{bad}");
    set_value(&c, "pr-cal-1", "3,30").await;
    // Walls that disagree change nothing.
    set_value(&c, "pr-cal-2", "6").await;
    click(&c, "pr-cal-fit").await;
    wait_js(
        &c,
        "return document.getElementById('pr-cal-result').textContent.includes('disagree')",
        "the refusal",
    )
    .await;
    if let Ok(path) = std::env::var("SWEEPCLAY_CALIBRATE_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    click(&c, "pr-save").await;
    let kept = wait_js(
        &c,
        &format!("return {IDLE} && typeof window.sweepclay.design.printer === 'object' && window.sweepclay.design.printer.e_per_mm3"),
        "the calibrated printer in the design",
    )
    .await;
    assert!((kept.as_f64().unwrap() - e).abs() < 1e-9, "{kept}");
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_refusal_shows_on_the_phones_shape_tab() {
    let Some(Session {
        driver: _driver,
        c,
        base,
        ..
    }) = Session::start().await
    else {
        return;
    };
    c.set_window_size(390, 844).await.unwrap();
    open_first_slice(&c, &base).await;
    click(&c, "new-pot").await;
    wait_js(
        &c,
        &format!("return {IDLE} && !window.sweepclay.design.profile_end && document.body.dataset.tab === 'editors'"),
        "a new pot on the Shape tab",
    )
    .await;
    let shown = "const e = document.getElementById('shape-error'); return e.getBoundingClientRect().height > 0 && e.textContent";
    assert_eq!(js(&c, shown).await, json!(false), "no error yet");
    // Twice the printer's height: refused, and said where the potter is.
    let h = js(
        &c,
        "const s = window.sweepclay, p = s.design.printer; return (typeof p === 'object' ? p : s.meta.presets.find((q) => q.name === (p || 'generic'))).build_volume[2] * 2",
    )
    .await;
    set_value(&c, "pot-height", &h.to_string()).await;
    let said = wait_js(&c, shown, "the refusal on the Shape tab").await;
    assert!(said.as_str().unwrap().contains("printer"), "{said}");
    // "Download G-code" says why it gives nothing, on this tab too.
    click(&c, "download-gcode").await;
    let said = wait_js(
        &c,
        "const e = document.getElementById('shape-error'); const t = e.getBoundingClientRect().height > 0 && e.textContent; return t && t.startsWith('No GCODE file') && t",
        "the download's refusal on the Shape tab",
    )
    .await;
    assert!(said.as_str().unwrap().contains("printer"), "{said}");
    if let Ok(path) = std::env::var("SWEEPCLAY_PHONE_ERROR_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    // A pot that fits clears it.
    set_value(&c, "pot-height", "60").await;
    wait_js(
        &c,
        &format!(
            "return {IDLE} && {} && document.getElementById('shape-error').textContent === ''",
            &PRINTABLE[7..]
        ),
        "the error cleared",
    )
    .await;
    no_page_errors_and_close(c).await;
}

/// Issue 59, point 4: a row height of 1e6 or 1e9 crashed the tab, 100000
/// moved the row to the bottom and blamed the point spacing, a width of
/// 1e9 was refused far from the field in control-point words. Each is now
/// refused beside the table in words, before anything is drawn or
/// sampled, and the design keeps its rows.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn typos_in_the_pot_rows_are_refused_beside_them() {
    let Some(Session {
        driver: _driver,
        c,
        base,
        ..
    }) = Session::start().await
    else {
        return;
    };
    open_first_slice(&c, &base).await;
    click(&c, "new-pot").await;
    wait_js(
        &c,
        &format!("return {IDLE} && !window.sweepclay.design.profile_end"),
        "a new pot",
    )
    .await;
    let before = js(
        &c,
        "return JSON.stringify(window.sweepclay.design.profile_start.control_points)",
    )
    .await;
    for (id, typed, says) in [
        ("pot-z1", "1e6", "height 1000000 mm: at most"),
        ("pot-z1", "1e9", "height 1000000000 mm: at most"),
        ("pot-z1", "100000", "height 100000 mm: at most"),
        ("pot-w1", "1e9", "width 1000000000 mm: at most"),
        ("pot-w0", "1e9", "width 1000000000 mm: at most"),
    ] {
        set_value(&c, id, typed).await;
        let said = wait_js(
            &c,
            &format!(
                "const e = document.getElementById('pot-error').textContent; return document.getElementById('{id}').classList.contains('bad') && e.length > 0 && e"
            ),
            &format!("{id} = {typed} refused"),
        )
        .await;
        let said = said.as_str().unwrap();
        assert!(said.starts_with(says), "{id} = {typed}: {said}");
        assert!(said.contains("four times"), "{said}");
        let now = js(
            &c,
            "return JSON.stringify(window.sweepclay.design.profile_start.control_points)",
        )
        .await;
        assert_eq!(now, before, "{id} = {typed} changed the design");
    }
    no_page_errors_and_close(c).await;
}

/// The print's width outside along x (mm) at each of `zs` in a G-code
/// text: over the moves within 0.7 mm of that height, the farthest bead
/// edges, each bead as wide as the `;WIDTH:` comment before it says.
fn widths_at(gcode: &str, zs: &[f64]) -> Vec<f64> {
    let (mut x, mut z, mut w) = (0.0f64, 0.0f64, 0.0f64);
    let mut span = vec![(f64::MAX, f64::MIN); zs.len()];
    for line in gcode.lines() {
        if let Some(v) = line.strip_prefix(";WIDTH:") {
            w = v.trim().parse().unwrap_or(w);
            continue;
        }
        let code = line.split(';').next().unwrap_or("");
        if !code.starts_with("G1 ") {
            continue;
        }
        for word in code.split_whitespace().skip(1) {
            let v = word[1..].parse::<f64>().unwrap_or(f64::NAN);
            match &word[..1] {
                "X" => x = v,
                "Z" => z = v,
                _ => {}
            }
        }
        for (k, &at) in zs.iter().enumerate() {
            if (z - at).abs() <= 0.7 {
                span[k] = (span[k].0.min(x - w / 2.0), span[k].1.max(x + w / 2.0));
            }
        }
    }
    span.iter().map(|(lo, hi)| hi - lo).collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_pot_typed_80_130_70_80_prints_those_widths() {
    let Some(Session {
        tmp: _tmp,
        downloads,
        driver: _driver,
        c,
        base,
        ..
    }) = Session::start().await
    else {
        return;
    };
    open_first_slice(&c, &base).await;
    click(&c, "new-pot").await;
    wait_js(
        &c,
        &format!("return {IDLE} && !window.sweepclay.design.profile_end"),
        "a new pot",
    )
    .await;
    // Four rows: add heights or remove them.
    loop {
        let n = js(
            &c,
            "return window.sweepclay.design.profile_start.control_points.length",
        )
        .await
        .as_u64()
        .unwrap();
        if n == 4 {
            break;
        }
        if n < 4 {
            click(&c, "pot-add").await;
        } else {
            click(&c, &format!("pot-del{}", n - 1)).await;
        }
        wait_js(
            &c,
            &format!(
                "return {IDLE} && document.querySelectorAll('#pot-rows tbody tr').length !== {n}"
            ),
            "a row added or removed",
        )
        .await;
    }
    // As a potter measures a pot: 80 mm across at the foot, 130 at the
    // belly (45 mm up), 70 at the neck (95 mm), 80 at the lip (120 mm).
    set_value(&c, "pot-height", "120").await;
    wait_js(
        &c,
        &format!("return {IDLE} && document.getElementById('pot-z3').value === '120'"),
        "120 mm",
    )
    .await;
    for (id, v) in [
        ("pot-z1", "45"),
        ("pot-z2", "95"),
        ("pot-w0", "80"),
        ("pot-w1", "130"),
        ("pot-w2", "70"),
        ("pot-w3", "80"),
    ] {
        set_value(&c, id, v).await;
        wait_js(
            &c,
            &format!("return {IDLE} && document.getElementById('{id}').value === '{v}'"),
            &format!("{id} = {v} in the table"),
        )
        .await;
    }
    wait_js(
        &c,
        &format!("return {IDLE} && {}", &PRINTABLE[7..]),
        "the pot printable",
    )
    .await;
    // The table still shows what was typed: the rows are on the curve.
    let rows = js(
        &c,
        "return Array.from(document.querySelectorAll('#pot-rows tbody tr')).map((tr) => Array.from(tr.querySelectorAll('input')).map((i) => i.value))",
    )
    .await;
    assert_eq!(
        rows,
        json!([["0", "80"], ["45", "130"], ["95", "70"], ["120", "80"]])
    );
    if let Ok(path) = std::env::var("SWEEPCLAY_POT_DESIGN") {
        let d = js(&c, "return JSON.stringify(window.sweepclay.design)").await;
        std::fs::write(&path, d.as_str().unwrap()).unwrap();
    }
    let (gcode, _) = download_printable(&c, &downloads, "no G-code of the pot").await;
    // The print is as wide outside as typed, as callipers read it (its
    // first turn just above the foot, its last just under the lip).
    let p = js(&c, "return { ...window.sweepclay.meta.params, ...(window.sweepclay.design.params || {}) }.layer_height").await;
    let h = p.as_f64().unwrap();
    // The foot is read on the floor, which still runs about a bead
    // outside the wall's first turn (issue 57, point 1: 82.0 mm for 80).
    let at = [h, 45.0, 95.0, 120.0 - h / 2.0];
    let got = widths_at(&gcode, &at);
    for (w, (want, z)) in got.iter().zip([80.0, 130.0, 70.0, 80.0].iter().zip(at)) {
        let within = if z == h { 2.5 } else { 0.5 };
        assert!(
            (w - want).abs() <= within,
            "at z {z}: {w:.1} mm printed outside, {want} mm typed; all {got:?}"
        );
    }
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_phones_header_keeps_the_daily_buttons_and_opens_the_rest_under_more() {
    let Some(Session {
        driver: _driver,
        c,
        base,
        ..
    }) = Session::start().await
    else {
        return;
    };
    c.set_window_size(390, 844).await.unwrap();
    open_first_slice(&c, &base).await;
    let seen = |id: &str| {
        format!("const r = document.getElementById('{id}').getBoundingClientRect(); return r.width > 0 && r.height > 0")
    };
    let header_h = "return document.querySelector('header').getBoundingClientRect().height";
    // Closed: New pot, Undo, Redo, Download G-code and More, in at most
    // two rows of 44 px buttons; the rest waits under More.
    let h = js(&c, header_h).await.as_f64().unwrap();
    assert!(h <= 120.0, "the header is {h} px tall");
    for id in ["new-pot", "undo", "redo", "download-gcode", "more"] {
        assert_eq!(js(&c, &seen(id)).await, json!(true), "{id} hidden");
    }
    for id in [
        "save",
        "open",
        "download-stl",
        "send-printer",
        "guide-open",
        "example",
    ] {
        assert_eq!(
            js(&c, &seen(id)).await,
            json!(false),
            "{id} shown while closed"
        );
    }
    // More opens them, each at least 44 px; using one closes the menu.
    tap_id(&c, "more").await;
    for id in [
        "save",
        "open",
        "download-stl",
        "send-printer",
        "guide-open",
        "example",
    ] {
        assert_eq!(
            js(&c, &seen(id)).await,
            json!(true),
            "{id} not shown under More"
        );
        let r = js(
            &c,
            &format!("const r = document.getElementById('{id}').getBoundingClientRect(); return [r.width, r.height]"),
        )
        .await;
        assert!(
            r[0].as_f64().unwrap() >= 44.0 && r[1].as_f64().unwrap() >= 44.0,
            "{id}: {r}"
        );
    }
    assert_eq!(
        js(
            &c,
            "return document.getElementById('more').getAttribute('aria-expanded')"
        )
        .await,
        json!("true")
    );
    if let Ok(path) = std::env::var("SWEEPCLAY_PHONE_MORE_SCREENSHOT") {
        std::fs::write(&path, c.screenshot().await.unwrap()).unwrap();
    }
    tap_id(&c, "guide-open").await;
    wait_js(
        &c,
        "return document.getElementById('guide').open",
        "the guide",
    )
    .await;
    assert_eq!(
        js(&c, &seen("save")).await,
        json!(false),
        "the menu stayed open"
    );
    tap_id(&c, "guide-close").await;
    // On a desktop there is no More: everything is in the header.
    c.set_window_size(1440, 900).await.unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(js(&c, &seen("more")).await, json!(false));
    assert_eq!(js(&c, &seen("save")).await, json!(true));
    no_page_errors_and_close(c).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_nozzle_diameter_sets_the_bead_widths_and_says_how() {
    let Some(Session {
        driver: _driver,
        c,
        base,
        ..
    }) = Session::start().await
    else {
        return;
    };
    open_first_slice(&c, &base).await;
    open_printer_dialog(&c).await;
    // A bore that is no bore is refused in the dialog, by name.
    set_value(&c, "pr-nozzle", "0").await;
    click(&c, "pr-save").await;
    let said = js(&c, "return document.getElementById('pr-error').textContent").await;
    assert!(
        said.as_str().unwrap().contains("nozzle diameter \"0\""),
        "{said}"
    );
    // A 4 mm nozzle: the note says what follows, and Use sets it.
    c.execute(
        "const e = document.getElementById('pr-nozzle'); e.value = '4'; e.dispatchEvent(new Event('input'));",
        vec![],
    )
    .await
    .unwrap();
    let note = js(
        &c,
        "return document.getElementById('pr-nozzle-note').textContent",
    )
    .await;
    assert!(
        note.as_str()
            .unwrap()
            .starts_with("Beads from 4 to 8 mm wide"),
        "{note}"
    );
    click(&c, "pr-save").await;
    let got = wait_js(
        &c,
        &format!("const d = window.sweepclay.design; return {IDLE} && d.printer.nozzle_diameter === 4 && [d.params.width_min, d.params.width_max]"),
        "the widths from the bore",
    )
    .await;
    assert_eq!(got, json!([4, 8]));
    wait_js(&c, PRINTABLE, "the design printable with 4 to 8 mm beads").await;
    // The settings show them.
    assert_eq!(
        js(&c, "return document.getElementById('p-width_min').value").await,
        json!("4")
    );
    no_page_errors_and_close(c).await;
}
