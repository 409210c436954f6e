//! Moonraker's API (moonraker.readthedocs.io, "Web API"): files are
//! uploaded to `POST /server/files/upload` (multipart, `root=gcodes`),
//! started by `POST /printer/print/start?filename=…`, listed by
//! `GET /server/files/list?root=gcodes`, and followed through
//! `GET /printer/objects/query?print_stats&virtual_sdcard`. An API key, when
//! the host asks for one, goes in `X-Api-Key`. Errors come as
//! `{"error": {"code": …, "message": …}}`.

use crate::{says_full, Link, LinkError, Status, SHORT, UPLOAD};
use reqwest::multipart::{Form, Part};

const HOST: &str = "Moonraker";

fn with_key(link: &Link, req: reqwest::RequestBuilder) -> reqwest::RequestBuilder {
    match &link.secret {
        Some(k) => req.header("X-Api-Key", k),
        None => req,
    }
}

/// Whether Moonraker's message says Klipper is not there.
fn says_no_klippy(text: &str) -> bool {
    let t = text.to_ascii_lowercase();
    t.contains("klippy")
        && (t.contains("disconnect")
            || t.contains("not connected")
            || t.contains("not ready")
            || t.contains("shutdown"))
}

async fn failure(link: &Link, resp: reqwest::Response) -> LinkError {
    let status = resp.status().as_u16();
    let text = link.text(resp).await;
    let message = serde_json::from_str::<serde_json::Value>(&text)
        .ok()
        .and_then(|v| {
            v.pointer("/error/message")
                .and_then(|m| m.as_str())
                .map(str::to_string)
        })
        .unwrap_or(text);
    match status {
        401 | 403 => LinkError::WrongKey {
            host: HOST,
            what: "API key",
        },
        413 | 507 => LinkError::Full { host: HOST },
        _ if says_full(&message) => LinkError::Full { host: HOST },
        _ if says_no_klippy(&message) => LinkError::NotConnected {
            host: HOST,
            state: message,
        },
        _ => link.refused(status, &message),
    }
}

pub(crate) async fn upload(link: &Link, name: &str, gcode: Vec<u8>) -> Result<String, LinkError> {
    let part = Part::bytes(gcode)
        .file_name(name.to_string())
        .mime_str("application/octet-stream")
        .map_err(|e| link.bad(e.to_string()))?;
    let form = Form::new().text("root", "gcodes").part("file", part);
    let req = with_key(link, link.http.post(link.at("server/files/upload"))).multipart(form);
    let resp = link.send(req, UPLOAD).await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp).await);
    }
    let v = link.json(resp).await?;
    // Moonraker 0.8 and later: {"result": {"item": {"path": …}}}; older
    // versions answered {"result": "name.gcode"}.
    v.pointer("/result/item/path")
        .or_else(|| v.pointer("/item/path"))
        .or_else(|| v.get("result").filter(|r| r.is_string()))
        .and_then(|p| p.as_str())
        .map(str::to_string)
        .ok_or_else(|| link.bad("no result.item.path in the upload's answer".into()))
}

pub(crate) async fn start(link: &Link, file: &str) -> Result<(), LinkError> {
    crate::ready_to_start(HOST, status(link).await?)?;
    let req =
        with_key(link, link.http.post(link.at("printer/print/start"))).query(&[("filename", file)]);
    let resp = link.send(req, SHORT).await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp).await);
    }
    Ok(())
}

pub(crate) async fn job(link: &Link, action: crate::JobAction) -> Result<(), LinkError> {
    let path = format!("printer/print/{}", action.name());
    let resp = link
        .send(with_key(link, link.http.post(link.at(&path))), SHORT)
        .await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp).await);
    }
    Ok(())
}

pub(crate) async fn status(link: &Link) -> Result<Status, LinkError> {
    // Without Klipper the printer objects do not exist (404): ask
    // Moonraker first whether Klipper is there.
    let resp = link
        .send(with_key(link, link.http.get(link.at("server/info"))), SHORT)
        .await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp).await);
    }
    let info = link.json(resp).await?;
    if info.pointer("/result/klippy_connected") == Some(&serde_json::Value::Bool(false)) {
        let state = info
            .pointer("/result/klippy_state")
            .and_then(|s| s.as_str())
            .unwrap_or("disconnected");
        return Ok(Status {
            state: format!("Klipper {state}"),
            printing: false,
            connected: false,
            file: None,
            progress: None,
        });
    }
    let req = with_key(
        link,
        link.http
            .get(link.at("printer/objects/query?print_stats&virtual_sdcard")),
    );
    let resp = link.send(req, SHORT).await?;
    if !resp.status().is_success() {
        return match failure(link, resp).await {
            // Moonraker up, Klipper not: a status all the same.
            LinkError::NotConnected { state, .. } => Ok(Status {
                state,
                printing: false,
                connected: false,
                file: None,
                progress: None,
            }),
            e => Err(e),
        };
    }
    let v = link.json(resp).await?;
    let stats = v
        .pointer("/result/status/print_stats")
        .ok_or_else(|| link.bad("no result.status.print_stats".into()))?;
    // print_stats.state: standby, printing, paused, complete, cancelled,
    // error (Klipper's docs, "Status reference").
    let state = stats
        .get("state")
        .and_then(|s| s.as_str())
        .unwrap_or("unknown")
        .to_string();
    Ok(Status {
        printing: matches!(state.as_str(), "printing" | "paused"),
        connected: state != "error",
        file: stats
            .get("filename")
            .and_then(|f| f.as_str())
            .filter(|f| !f.is_empty())
            .map(str::to_string),
        progress: v
            .pointer("/result/status/virtual_sdcard/progress")
            .and_then(|p| p.as_f64()),
        state,
    })
}

pub(crate) async fn files(link: &Link) -> Result<Vec<String>, LinkError> {
    let req =
        with_key(link, link.http.get(link.at("server/files/list"))).query(&[("root", "gcodes")]);
    let resp = link.send(req, SHORT).await?;
    if !resp.status().is_success() {
        return Err(failure(link, resp).await);
    }
    let v = link.json(resp).await?;
    let list = v
        .get("result")
        .and_then(|r| r.as_array())
        .ok_or_else(|| link.bad("no result list".into()))?;
    Ok(list
        .iter()
        .filter_map(|f| {
            f.get("path")
                .or_else(|| f.get("filename"))
                .and_then(|p| p.as_str())
                .map(str::to_string)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn klippys_absence_is_recognised() {
        assert!(says_no_klippy("Klippy Disconnected"));
        assert!(says_no_klippy("Klippy Host not connected"));
        assert!(!says_no_klippy("File not found"));
    }
}
