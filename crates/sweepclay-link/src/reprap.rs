//! RepRapFirmware's HTTP requests in standalone mode (Duet3D's wiki
//! "HTTP requests" and its `OpenAPI.yaml`), as Duet Web Control sends them:
//!
//! - `GET /rr_connect?password=…&time=…&sessionKey=yes` → `{"err": 0,
//!   "sessionKey": N}` (err 1: wrong password; 2: no more sessions); the
//!   key, when given, goes back as `X-Session-Key`;
//! - `POST /rr_upload?name=0:/gcodes/F&time=…`, the file as the body →
//!   `{"err": 0}`;
//! - `GET /rr_gcode?gcode=M32 "0:/gcodes/F"` starts it → `{"buff": N}`;
//! - `GET /rr_model?key=state` and `?key=job` (RRF 3) for the status and
//!   the file position;
//! - `GET /rr_filelist?dir=0:/gcodes` → `{"files": [{"type": "f", "name":
//!   …}], "next": 0}`;
//! - `GET /rr_disconnect` ends the session.
//!
//! Every request but `rr_connect` is answered 401 without a session. No
//! RepRapFirmware server can be installed here: this client is tested
//! against the documented forms only (docs/PRINTING.md).

use crate::{says_full, Link, LinkError, Status, SHORT, UPLOAD};

const HOST: &str = "the Duet (RepRapFirmware)";

/// The folder RepRapFirmware prints from.
const GCODES: &str = "0:/gcodes";

/// An open session: the key to send back, if the board gave one.
struct Session {
    key: Option<String>,
}

/// `YYYY-MM-DDTHH:MM:SS` (UTC; the board's clock has no zone) for `secs`
/// since 1970.
pub(crate) fn datetime(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    // Howard Hinnant's civil-from-days.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

fn now() -> String {
    datetime(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs()),
    )
}

fn with_session(req: reqwest::RequestBuilder, s: &Session) -> reqwest::RequestBuilder {
    match &s.key {
        Some(k) => req.header("X-Session-Key", k),
        None => req,
    }
}

async fn connect(link: &Link) -> Result<Session, LinkError> {
    let mut query = vec![("time", now()), ("sessionKey", "yes".to_string())];
    // Without a password the board takes its default, `reprap`.
    if let Some(p) = &link.secret {
        query.insert(0, ("password", p.clone()));
    }
    let req = link.http.get(link.at("rr_connect")).query(&query);
    let resp = link.send(req, SHORT).await?;
    let status = resp.status().as_u16();
    if !resp.status().is_success() {
        return Err(link.refused(status, &link.text(resp).await));
    }
    let v = link.json(resp).await?;
    match v.get("err").and_then(|e| e.as_i64()) {
        Some(0) => Ok(Session {
            key: v.get("sessionKey").map(|k| match k {
                serde_json::Value::String(s) => s.clone(),
                other => other.to_string(),
            }),
        }),
        Some(1) => Err(LinkError::WrongKey {
            host: HOST,
            what: "password",
        }),
        Some(2) => Err(link.refused(
            status,
            "no more sessions: close Duet Web Control in another browser and send again",
        )),
        _ => Err(link.bad("rr_connect's answer has no `err`".into())),
    }
}

async fn disconnect(link: &Link, s: &Session) {
    // Best effort: the board drops idle sessions by itself.
    let _ = link
        .send(
            with_session(link.http.get(link.at("rr_disconnect")), s),
            SHORT,
        )
        .await;
}

/// Runs `f` inside a session, closing it whatever `f` gives.
async fn in_session<T>(
    link: &Link,
    f: impl AsyncFnOnce(&Session) -> Result<T, LinkError>,
) -> Result<T, LinkError> {
    let s = connect(link).await?;
    let out = f(&s).await;
    disconnect(link, &s).await;
    out
}

/// A JSON answer; 401 means the session was refused.
async fn answer(link: &Link, resp: reqwest::Response) -> Result<serde_json::Value, LinkError> {
    let status = resp.status().as_u16();
    match status {
        200..=299 => link.json(resp).await,
        401 | 403 => Err(LinkError::WrongKey {
            host: HOST,
            what: "password",
        }),
        _ => Err(link.refused(status, &link.text(resp).await)),
    }
}

pub(crate) async fn upload(link: &Link, name: &str, gcode: Vec<u8>) -> Result<String, LinkError> {
    let path = format!("{GCODES}/{name}");
    in_session(link, async |s| {
        let req = link
            .http
            .post(link.at("rr_upload"))
            .query(&[("name", path.as_str()), ("time", now().as_str())])
            .header("Content-Type", "application/octet-stream")
            .body(gcode);
        let resp = link.send(with_session(req, s), UPLOAD).await?;
        let status = resp.status().as_u16();
        let v = match answer(link, resp).await {
            Err(LinkError::Refused { message, .. }) if says_full(&message) => {
                return Err(LinkError::Full { host: HOST })
            }
            other => other?,
        };
        match v.get("err").and_then(|e| e.as_i64()) {
            Some(0) => Ok(path.clone()),
            // The board says only that it could not write the file: on a
            // standalone Duet that is a full or missing SD card.
            Some(_) => Err(link.refused(
                status,
                "the board could not write the file: its SD card may be full or missing",
            )),
            None => Err(link.bad("rr_upload's answer has no `err`".into())),
        }
    })
    .await
}

/// The board's state and job, in one session.
async fn state(link: &Link, s: &Session) -> Result<Status, LinkError> {
    let get = |key: &'static str| {
        with_session(
            link.http
                .get(link.at("rr_model"))
                .query(&[("key", key), ("flags", "d99fn")]),
            s,
        )
    };
    let v = answer(link, link.send(get("state"), SHORT).await?).await?;
    let state = v
        .pointer("/result/status")
        .and_then(|s| s.as_str())
        .ok_or_else(|| link.bad("rr_model?key=state has no result.status".into()))?
        .to_string();
    let job = answer(link, link.send(get("job"), SHORT).await?).await?;
    let file = job
        .pointer("/result/file/fileName")
        .and_then(|f| f.as_str())
        .map(str::to_string);
    let size = job.pointer("/result/file/size").and_then(|x| x.as_f64());
    let pos = job.pointer("/result/filePosition").and_then(|x| x.as_f64());
    // ObjectModel state.status: idle, busy, processing, paused, pausing,
    // resuming, cancelling, simulating, halted, off, updating, starting.
    let printing = matches!(
        state.as_str(),
        "processing" | "paused" | "pausing" | "resuming" | "cancelling" | "simulating"
    );
    Ok(Status {
        printing,
        connected: !matches!(state.as_str(), "halted" | "off" | "updating"),
        progress: match (pos, size) {
            (Some(p), Some(n)) if n > 0.0 => Some((p / n).clamp(0.0, 1.0)),
            _ => None,
        },
        file: file.filter(|_| printing),
        state,
    })
}

pub(crate) async fn start(link: &Link, file: &str) -> Result<(), LinkError> {
    in_session(link, async |s| {
        crate::ready_to_start(HOST, state(link, s).await?)?;
        let code = format!("M32 \"{file}\"");
        let req = link
            .http
            .get(link.at("rr_gcode"))
            .query(&[("gcode", code.as_str())]);
        let v = answer(link, link.send(with_session(req, s), SHORT).await?).await?;
        if v.get("buff").is_none() {
            return Err(link.bad("rr_gcode's answer has no `buff`".into()));
        }
        Ok(())
    })
    .await
}

pub(crate) async fn job(link: &Link, action: crate::JobAction) -> Result<(), LinkError> {
    use crate::JobAction::*;
    // RepRapFirmware: M25 pauses, M24 resumes, M0 after a pause cancels.
    let codes: &[&str] = match action {
        Pause => &["M25"],
        Resume => &["M24"],
        Cancel => &["M25", "M0"],
    };
    in_session(link, async |s| {
        for code in codes {
            let req = link
                .http
                .get(link.at("rr_gcode"))
                .query(&[("gcode", *code)]);
            let v = answer(link, link.send(with_session(req, s), SHORT).await?).await?;
            if v.get("buff").is_none() {
                return Err(link.bad("rr_gcode's answer has no `buff`".into()));
            }
        }
        Ok(())
    })
    .await
}

pub(crate) async fn status(link: &Link) -> Result<Status, LinkError> {
    in_session(link, async |s| state(link, s).await).await
}

pub(crate) async fn files(link: &Link) -> Result<Vec<String>, LinkError> {
    in_session(link, async |s| {
        let mut out = Vec::new();
        let mut first = 0i64;
        // The board pages long listings: `next` is where the next starts, 0
        // at the end. At most 100 pages.
        for _ in 0..100 {
            let req = link
                .http
                .get(link.at("rr_filelist"))
                .query(&[("dir", GCODES.to_string()), ("first", first.to_string())]);
            let v = answer(link, link.send(with_session(req, s), SHORT).await?).await?;
            let files = v
                .get("files")
                .and_then(|f| f.as_array())
                .ok_or_else(|| link.bad("rr_filelist's answer has no `files`".into()))?;
            out.extend(files.iter().filter_map(|f| {
                (f.get("type").and_then(|t| t.as_str()) == Some("f"))
                    .then(|| f.get("name").and_then(|n| n.as_str()))
                    .flatten()
                    .map(|n| format!("{GCODES}/{n}"))
            }));
            first = v.get("next").and_then(|n| n.as_i64()).unwrap_or(0);
            if first == 0 {
                break;
            }
        }
        Ok(out)
    })
    .await
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn datetimes_are_the_boards_form() {
        assert_eq!(datetime(0), "1970-01-01T00:00:00");
        // The wiki's example, 2019-12-13T21:27:00.
        assert_eq!(datetime(1_576_272_420), "2019-12-13T21:27:00");
        assert_eq!(datetime(951_782_400), "2000-02-29T00:00:00");
    }
}
