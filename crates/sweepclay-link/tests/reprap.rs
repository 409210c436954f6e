//! The RepRapFirmware client against a stand-in that answers as Duet3D's
//! wiki "HTTP requests" documents (no RepRapFirmware server can be
//! installed here): it checks every request's form and answers with the
//! documented JSON.

use axum::extract::{Query, State};
use axum::http::{HeaderMap, StatusCode};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use sweepclay_link::{Kind, Link, LinkError};

#[derive(Default)]
struct Board {
    password: String,
    /// Session keys handed out and not yet closed.
    sessions: Vec<String>,
    files: HashMap<String, Vec<u8>>,
    /// The file printing, and how far (bytes).
    printing: Option<(String, usize)>,
    /// `rr_upload` answers err 1 (a full card).
    full: bool,
    /// Every request's path and query, for the assertions.
    log: Vec<String>,
}

type Shared = Arc<Mutex<Board>>;
type Q = Query<HashMap<String, String>>;

/// A datetime as the wiki spells it: `2019-12-13T21:27:00`.
fn is_datetime(s: &str) -> bool {
    let b = s.as_bytes();
    b.len() == 19
        && b.iter().enumerate().all(|(i, c)| match i {
            4 | 7 => *c == b'-',
            10 => *c == b'T',
            13 | 16 => *c == b':',
            _ => c.is_ascii_digit(),
        })
}

/// 401 unless the request carries an open session's key.
fn session(b: &Board, h: &HeaderMap) -> Result<(), StatusCode> {
    let key = h.get("X-Session-Key").and_then(|k| k.to_str().ok());
    match key {
        Some(k) if b.sessions.iter().any(|s| s == k) => Ok(()),
        _ => Err(StatusCode::UNAUTHORIZED),
    }
}

async fn connect(State(s): State<Shared>, Query(q): Q) -> Json<Value> {
    let mut b = s.lock().unwrap();
    b.log.push(format!("rr_connect {q:?}"));
    assert!(is_datetime(&q["time"]), "time={}", q["time"]);
    if q.get("password").map(String::as_str).unwrap_or("reprap") != b.password {
        return Json(json!({"err": 1}));
    }
    let key = format!("{}", 1000 + b.sessions.len());
    b.sessions.push(key.clone());
    Json(
        json!({"err": 0, "sessionTimeout": 8000, "boardType": "duet3mb6hc", "apiLevel": 1,
                "sessionKey": key.parse::<u32>().unwrap()}),
    )
}

async fn disconnect(State(s): State<Shared>, h: HeaderMap) -> Json<Value> {
    let mut b = s.lock().unwrap();
    let key = h
        .get("X-Session-Key")
        .and_then(|k| k.to_str().ok())
        .unwrap_or("");
    b.sessions.retain(|s| s != key);
    Json(json!({"err": 0}))
}

async fn upload(
    State(s): State<Shared>,
    h: HeaderMap,
    Query(q): Q,
    body: axum::body::Bytes,
) -> Result<Json<Value>, StatusCode> {
    let mut b = s.lock().unwrap();
    session(&b, &h)?;
    b.log.push(format!("rr_upload name={}", q["name"]));
    assert!(is_datetime(&q["time"]));
    if b.full {
        return Ok(Json(json!({"err": 1})));
    }
    b.files.insert(q["name"].clone(), body.to_vec());
    Ok(Json(json!({"err": 0})))
}

async fn gcode(
    State(s): State<Shared>,
    h: HeaderMap,
    Query(q): Q,
) -> Result<Json<Value>, StatusCode> {
    let mut b = s.lock().unwrap();
    session(&b, &h)?;
    b.log.push(format!("rr_gcode {}", q["gcode"]));
    if let Some(file) = q["gcode"]
        .strip_prefix("M32 \"")
        .and_then(|f| f.strip_suffix('"'))
    {
        assert!(
            b.files.contains_key(file),
            "M32 of a file the board lacks: {file}"
        );
        b.printing = Some((file.to_string(), 0));
    }
    Ok(Json(json!({"buff": 255})))
}

async fn model(
    State(s): State<Shared>,
    h: HeaderMap,
    Query(q): Q,
) -> Result<Json<Value>, StatusCode> {
    let mut b = s.lock().unwrap();
    session(&b, &h)?;
    let printing = b.printing.clone();
    Ok(Json(match q["key"].as_str() {
        "state" => json!({"key": "state", "flags": q["flags"], "result": {
            "status": if printing.is_some() { "processing" } else { "idle" }}}),
        "job" => {
            let (name, pos) = printing.unwrap_or_default();
            let size = b.files.get(&name).map_or(0, Vec::len);
            // Each status read moves the print on by half.
            if let Some(p) = b.printing.as_mut() {
                p.1 = (pos + size / 2 + 1).min(size);
                if p.1 == size {
                    b.printing = None;
                }
            }
            json!({"key": "job", "flags": q["flags"], "result": {
                "file": {"fileName": name, "size": size}, "filePosition": pos}})
        }
        other => panic!("rr_model key {other}"),
    }))
}

async fn filelist(
    State(s): State<Shared>,
    h: HeaderMap,
    Query(q): Q,
) -> Result<Json<Value>, StatusCode> {
    let b = s.lock().unwrap();
    session(&b, &h)?;
    assert_eq!(q["dir"], "0:/gcodes");
    let files: Vec<Value> = b
        .files
        .keys()
        .map(|k| {
            json!({"type": "f", "name": k.trim_start_matches("0:/gcodes/"), "size": 1,
                        "date": "2026-12-04T10:00:00"})
        })
        .collect();
    Ok(Json(
        json!({"dir": "0:/gcodes", "first": 0, "files": files, "next": 0}),
    ))
}

async fn board(password: &str) -> (String, Shared) {
    let shared: Shared = Arc::new(Mutex::new(Board {
        password: password.into(),
        ..Board::default()
    }));
    let app = Router::new()
        .route("/rr_connect", get(connect))
        .route("/rr_disconnect", get(disconnect))
        .route("/rr_upload", post(upload))
        .route("/rr_gcode", get(gcode))
        .route("/rr_model", get(model))
        .route("/rr_filelist", get(filelist))
        .with_state(shared.clone());
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let url = format!("http://{}", listener.local_addr().unwrap());
    tokio::spawn(async move { axum::serve(listener, app).await.unwrap() });
    (url, shared)
}

#[tokio::test]
async fn a_duet_gets_the_file_in_gcodes_starts_it_with_m32_and_reports_progress() {
    let (url, board) = board("clay").await;
    let link = Link::new(Kind::RepRap, &url, Some("clay".into())).unwrap();
    let stored = link.upload("pot", b"G1 X1 E1\n".repeat(100)).await.unwrap();
    assert_eq!(stored, "0:/gcodes/pot.gcode");
    assert_eq!(link.files().await.unwrap(), vec![stored.clone()]);
    link.start(&stored).await.unwrap();
    let s = link.status().await.unwrap();
    assert!(s.printing && s.connected, "{s:?}");
    assert_eq!(s.file.as_deref(), Some("0:/gcodes/pot.gcode"));
    assert_eq!(s.progress, Some(0.0));
    // Busy: a second start is refused, naming the file.
    let e = link.start(&stored).await.unwrap_err();
    assert_eq!(
        e,
        LinkError::Busy {
            file: stored.clone()
        }
    );
    // Two more reads and the stand-in has finished.
    let _ = link.status().await.unwrap();
    let s = link.status().await.unwrap();
    assert!(!s.printing, "{s:?}");
    let b = board.lock().unwrap();
    // Every session was closed again, and the requests had their forms.
    assert!(
        b.sessions.is_empty(),
        "sessions left open: {:?}",
        b.sessions
    );
    assert!(
        b.log
            .contains(&"rr_gcode M32 \"0:/gcodes/pot.gcode\"".to_string()),
        "{:?}",
        b.log
    );
    assert!(b
        .log
        .contains(&"rr_upload name=0:/gcodes/pot.gcode".to_string()));
}

/// Issue 59, point 3: a Duet's print is paused with M25, resumed with
/// M24 and cancelled with M25 then M0, each in a session it closes.
#[tokio::test]
async fn a_duet_pauses_resumes_and_cancels_with_m25_m24_m0() {
    let (url, board) = board("clay").await;
    let link = Link::new(Kind::RepRap, &url, Some("clay".into())).unwrap();
    for action in [
        sweepclay_link::JobAction::Pause,
        sweepclay_link::JobAction::Resume,
        sweepclay_link::JobAction::Cancel,
    ] {
        link.job(action).await.unwrap();
    }
    let b = board.lock().unwrap();
    let sent: Vec<&String> = b.log.iter().filter(|l| l.starts_with("rr_gcode")).collect();
    assert_eq!(
        sent,
        [
            "rr_gcode M25",
            "rr_gcode M24",
            "rr_gcode M25",
            "rr_gcode M0"
        ]
    );
    assert!(
        b.sessions.is_empty(),
        "sessions left open: {:?}",
        b.sessions
    );
}

#[tokio::test]
async fn a_wrong_password_and_a_full_card_are_plain_messages() {
    let (url, state) = board("clay").await;
    let wrong = Link::new(Kind::RepRap, &url, Some("glaze".into())).unwrap();
    let e = wrong.upload("pot", b"G1 X1\n".to_vec()).await.unwrap_err();
    assert!(e.to_string().contains("refused the password"), "{e}");
    state.lock().unwrap().full = true;
    let link = Link::new(Kind::RepRap, &url, Some("clay".into())).unwrap();
    let e = link.upload("pot", b"G1 X1\n".to_vec()).await.unwrap_err();
    assert!(e.to_string().contains("SD card may be full"), "{e}");
    // The board's default password is `reprap`: no secret sends that.
    let (url, _) = board("reprap").await;
    let open = Link::new(Kind::RepRap, &url, None).unwrap();
    assert!(open.files().await.unwrap().is_empty());
}
