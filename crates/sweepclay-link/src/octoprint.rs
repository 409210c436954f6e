//! OctoPrint's REST API (docs.octoprint.org, "REST API"): files are
//! uploaded to `POST /api/files/local` as multipart form data, selected and
//! started by `POST /api/files/local/{path}` with `{"command": "select",
//! "print": true}`, and followed by `GET /api/job`. Every request carries
//! the `X-Api-Key` header; a wrong key is answered 403 (401 before 1.5).

use crate::{says_full, Link, LinkError, Status, SHORT, UPLOAD};
use reqwest::multipart::{Form, Part};

const HOST: &str = "OctoPrint";

fn with_key(link: &Link, req: reqwest::RequestBuilder) -> reqwest::RequestBuilder {
    match &link.secret {
        Some(k) => req.header("X-Api-Key", k),
        None => req,
    }
}

/// The error for a non-success answer.
async fn failure(link: &Link, resp: reqwest::Response, doing: Doing) -> LinkError {
    let status = resp.status().as_u16();
    let text = link.text(resp).await;
    match status {
        // Without a valid key OctoPrint takes a POST for a browser's and
        // refuses it for its CSRF token.
        401 | 403 => LinkError::WrongKey {
            host: HOST,
            what: "API key",
        },
        400 if text.contains("CSRF") => LinkError::WrongKey {
            host: HOST,
            what: "API key",
        },
        413 | 507 => LinkError::Full { host: HOST },
        _ if says_full(&text) => LinkError::Full { host: HOST },
        // 409: the file is the one printing (upload), or the printer is
        // not operational or busy (start).
        409 => match (doing, status_of(link).await) {
            (_, Ok(s)) if s.printing => LinkError::Busy {
                file: s.file.unwrap_or_default(),
            },
            (Doing::Start, Ok(s)) => LinkError::NotConnected {
                host: HOST,
                state: s.state,
            },
            _ => link.refused(status, &text),
        },
        _ => link.refused(status, &text),
    }
}

#[derive(Clone, Copy)]
enum Doing {
    Upload,
    Start,
    Job,
}

pub(crate) async fn upload(link: &Link, name: &str, gcode: Vec<u8>) -> Result<String, LinkError> {
    let part = Part::bytes(gcode)
        .file_name(name.to_string())
        .mime_str("application/octet-stream")
        .map_err(|e| link.bad(e.to_string()))?;
    let form = Form::new().part("file", part);
    let req = with_key(link, link.http.post(link.at("api/files/local"))).multipart(form);
    let resp = link.send(req, UPLOAD).await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp, Doing::Upload).await);
    }
    let v = link.json(resp).await?;
    v.pointer("/files/local/path")
        .and_then(|p| p.as_str())
        .map(str::to_string)
        .ok_or_else(|| link.bad("no files.local.path in the upload's answer".into()))
}

pub(crate) async fn start(link: &Link, file: &str) -> Result<(), LinkError> {
    crate::ready_to_start(HOST, status_of(link).await?)?;
    let path = format!("api/files/local/{}", encode_path(file));
    let req = with_key(link, link.http.post(link.at(&path)))
        .json(&serde_json::json!({"command": "select", "print": true}));
    let resp = link.send(req, SHORT).await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp, Doing::Start).await);
    }
    Ok(())
}

pub(crate) async fn job(link: &Link, action: crate::JobAction) -> Result<(), LinkError> {
    use crate::JobAction::*;
    let body = match action {
        Pause => serde_json::json!({"command": "pause", "action": "pause"}),
        Resume => serde_json::json!({"command": "pause", "action": "resume"}),
        Cancel => serde_json::json!({"command": "cancel"}),
    };
    let req = with_key(link, link.http.post(link.at("api/job"))).json(&body);
    let resp = link.send(req, SHORT).await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp, Doing::Job).await);
    }
    Ok(())
}

/// Each segment of a stored path, percent-encoded.
fn encode_path(path: &str) -> String {
    path.split('/')
        .map(|seg| {
            seg.bytes()
                .map(|b| match b {
                    b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' => {
                        (b as char).to_string()
                    }
                    _ => format!("%{b:02X}"),
                })
                .collect::<String>()
        })
        .collect::<Vec<_>>()
        .join("/")
}

async fn status_of(link: &Link) -> Result<Status, LinkError> {
    let resp = link
        .send(with_key(link, link.http.get(link.at("api/job"))), SHORT)
        .await?;
    if !resp.status().is_success() {
        let status = resp.status().as_u16();
        return Err(match status {
            401 | 403 => LinkError::WrongKey {
                host: HOST,
                what: "API key",
            },
            _ => link.refused(status, &link.text(resp).await),
        });
    }
    let v = link.json(resp).await?;
    let state = v
        .get("state")
        .and_then(|s| s.as_str())
        .ok_or_else(|| link.bad("no `state` in /api/job".into()))?
        .to_string();
    // OctoPrint's states (octoprint.util.comm): Printing, Pausing, Paused,
    // Resuming, Finishing, Cancelling, Starting, … are a print under way;
    // Offline, Error, Closed and Connecting mean no printer.
    let first = state.split([' ', ':']).next().unwrap_or("");
    let printing = matches!(
        first,
        "Printing" | "Pausing" | "Paused" | "Resuming" | "Finishing" | "Cancelling" | "Starting"
    );
    let connected = !matches!(
        first,
        "Offline" | "Error" | "Closed" | "Connecting" | "Opening" | "Detecting" | "Unknown"
    );
    Ok(Status {
        printing,
        connected,
        file: v
            .pointer("/job/file/path")
            .and_then(|p| p.as_str())
            .map(str::to_string),
        progress: v
            .pointer("/progress/completion")
            .and_then(|c| c.as_f64())
            .map(|c| (c / 100.0).clamp(0.0, 1.0)),
        state,
    })
}

pub(crate) async fn status(link: &Link) -> Result<Status, LinkError> {
    status_of(link).await
}

pub(crate) async fn files(link: &Link) -> Result<Vec<String>, LinkError> {
    let req =
        with_key(link, link.http.get(link.at("api/files/local"))).query(&[("recursive", "true")]);
    let resp = link.send(req, SHORT).await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp, Doing::Upload).await);
    }
    let v = link.json(resp).await?;
    let mut out = Vec::new();
    collect(v.get("files"), &mut out);
    Ok(out)
}

/// The paths of a file listing's files, folders walked.
fn collect(files: Option<&serde_json::Value>, out: &mut Vec<String>) {
    for f in files.and_then(|f| f.as_array()).into_iter().flatten() {
        if f.get("type").and_then(|t| t.as_str()) == Some("folder") {
            collect(f.get("children"), out);
        } else if let Some(p) = f.get("path").and_then(|p| p.as_str()) {
            out.push(p.to_string());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stored_paths_are_encoded_segment_by_segment() {
        assert_eq!(encode_path("pots/my vase.gcode"), "pots/my%20vase.gcode");
    }

    #[test]
    fn listings_are_walked_into_folders() {
        let v = serde_json::json!({"files": [
            {"type": "machinecode", "path": "a.gcode"},
            {"type": "folder", "children": [{"type": "machinecode", "path": "pots/b.gcode"}]}
        ]});
        let mut out = Vec::new();
        collect(v.get("files"), &mut out);
        assert_eq!(out, ["a.gcode", "pots/b.gcode"]);
    }
}
