//! The modeler's printer routes (docs/PRINTING.md, docs/CALIBRATION.md):
//! send the checked G-code to the print host a design's printer names,
//! follow the print, keep the host's key on this machine, and the clay
//! calibration print and its fit. The HTTP talk to the host is
//! `sweepclay-link`'s; the calibration is `sweepclay_core::calibrate`.

use crate::{api, bytes, with_design, ApiError, Shared};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{Query, State};
use axum::http::header;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SendQuery {
    /// Start printing once uploaded.
    start: Option<bool>,
}

/// What `/api/send` did.
#[derive(serde::Serialize)]
pub(crate) struct Sent {
    /// The name the host stored the file under.
    file: String,
    /// The host's kind and address.
    kind: &'static str,
    url: String,
    /// Whether the print was started.
    started: bool,
}

/// A link to the print host a design's printer names, with its saved key.
///
/// Only a host the user saved on this machine (the printer dialog's Save,
/// or `sweepclay send --save-key`) is reached: a design or a request can
/// name any address, and the server must not become a way to reach it or
/// to hand it a key. `$SWEEPCLAY_HOST_KEY` is never read here
/// (docs/PRINTING.md, "What the link sends where").
fn link_for(
    host: &sweepclay_core::printer::PrintHost,
    key: &'static str,
) -> Result<sweepclay_link::Link, ApiError> {
    let kind = sweepclay_link::Kind::from_name(host.kind.name()).ok_or_else(|| {
        ApiError::new(422, "unknown print host kind").with_key(format!("{key}.kind"))
    })?;
    let keys = sweepclay_link::keys::default_path();
    let secret = sweepclay_link::keys::saved(keys.as_deref(), &host.url)
        .map_err(|e| ApiError::new(500, format!("the keys file: {e}")))?
        .ok_or_else(|| {
            ApiError::new(
                403,
                format!(
                    "the print host {} is not one saved on this computer: open the printer dialog, check the address and save the printer, then send again",
                    sweepclay_link::normalize_url(&host.url)
                ),
            )
            .with_key(format!("{key}.url"))
        })?;
    sweepclay_link::Link::with_certificate(kind, &host.url, secret, host.cert_sha256.as_deref())
        .map_err(|e| ApiError::new(422, e.to_string()).with_key(format!("{key}.url")))
}

/// A print host's refusal as the page shows it: 502, the host's sentence.
fn host_error(e: sweepclay_link::LinkError) -> ApiError {
    // The page says what to do on the page, not on a command line.
    if let sweepclay_link::LinkError::WrongKey { host, what } = e {
        return ApiError::new(
            502,
            format!("{host} refused the {what}: copy it again from {host}'s settings into \"key\" in Edit printer…, and save"),
        );
    }
    if let sweepclay_link::LinkError::Certificate { sha256, .. } = &e {
        return ApiError::new(
            502,
            format!("{e}: paste {sha256} into \"certificate\" in Edit printer…, and save"),
        )
        .with_key("printer.host.cert_sha256");
    }
    ApiError::new(502, e.to_string())
}

/// Slices the design exactly as `/api/gcode` downloads it (checked: a
/// file that fails the check is never sent), uploads it to the print host
/// its printer names, and starts it if asked (docs/PRINTING.md).
pub(crate) async fn send(
    State(limits): State<Shared>,
    query: Result<Query<SendQuery>, axum::extract::rejection::QueryRejection>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<Sent>, ApiError> {
    let Query(q) = query.map_err(|e| ApiError::new(400, e.body_text()))?;
    let (gcode, host, name) = with_design(limits, body, |d, c| {
        let printer = d.design().printer.resolve()?;
        let host = printer.host.clone().ok_or_else(|| {
            ApiError::new(
                422,
                "the printer names no print host: add one in the printer dialog (Send to printer)",
            )
            .with_key("printer.host")
        })?;
        let text = api::gcode(&d, c)?;
        Ok((text, host, d.design().name.clone()))
    })
    .await?;
    let link = link_for(&host, "printer.host")?;
    let file = link
        .upload(&name, gcode.into_bytes())
        .await
        .map_err(host_error)?;
    let start = q.start.unwrap_or(false);
    if start {
        link.start(&file).await.map_err(host_error)?;
    }
    Ok(Json(Sent {
        file,
        kind: host.kind.name(),
        url: link.url(),
        started: start,
    }))
}

/// What the print host says the printer is doing; the body is the
/// printer's `host` object.
pub(crate) async fn host_status(
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<sweepclay_link::Status>, ApiError> {
    let host: sweepclay_core::printer::PrintHost = serde_json::from_slice(&bytes(body)?)
        .map_err(|e| ApiError::new(400, format!("host: {e}")))?;
    host.validate("host")?;
    link_for(&host, "host")?
        .status()
        .await
        .map(Json)
        .map_err(host_error)
}

/// What to do with the print under way, and on which host.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct HostJob {
    /// The printer's `host` object.
    host: sweepclay_core::printer::PrintHost,
    /// "pause", "resume" or "cancel".
    action: sweepclay_link::JobAction,
}

/// Pauses, resumes or cancels the print on a saved host, then says what
/// the printer is doing (docs/PRINTING.md, "Pause, resume, cancel").
pub(crate) async fn host_job(
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<sweepclay_link::Status>, ApiError> {
    let j: HostJob = serde_json::from_slice(&bytes(body)?)
        .map_err(|e| ApiError::new(400, format!("job: {e}")))?;
    j.host.validate("host")?;
    let link = link_for(&j.host, "host")?;
    link.job(j.action).await.map_err(host_error)?;
    link.status().await.map(Json).map_err(host_error)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct HostKey {
    url: String,
    /// The key; missing or empty keeps the one saved (the page never
    /// reads a key back, so its field is empty when a printer is edited).
    #[serde(default)]
    key: Option<String>,
    /// Forget the host and its key.
    #[serde(default)]
    forget: bool,
}

/// Saves a print host (and its key, if given) in the keys file on this
/// machine: the hosts the server will talk to. The page never reads a key
/// back (docs/PRINTING.md, "Keys").
pub(crate) async fn host_key(
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<serde_json::Value>, ApiError> {
    let k: HostKey = serde_json::from_slice(&bytes(body)?)
        .map_err(|e| ApiError::new(400, format!("key: {e}")))?;
    sweepclay_link::check_url(&k.url)
        .map_err(|e| ApiError::new(422, e.to_string()).with_key("url"))?;
    let path = sweepclay_link::keys::default_path()
        .ok_or_else(|| ApiError::new(500, "no configuration directory (HOME is not set)"))?;
    tokio::task::spawn_blocking(move || {
        use sweepclay_link::keys::{update, Change};
        let key = k.key.as_deref().map(str::trim).unwrap_or("");
        let change = match (k.forget, key) {
            (true, _) => Change::Forget,
            (false, "") => Change::Keep,
            (false, key) => Change::Key(key),
        };
        update(&path, &k.url, change)
    })
    .await
    .map_err(|e| ApiError::new(500, e.to_string()))?
    .map_err(|e| ApiError::new(500, format!("saving the key: {e}")))?;
    Ok(Json(serde_json::json!({"saved": true})))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CalibrationAsk {
    /// The printer: a preset name or a profile.
    printer: sweepclay_core::PrinterRef,
    /// The design's parameters (layer height, bead widths); omitted keys
    /// take their defaults.
    #[serde(default)]
    params: Option<sweepclay_core::Params>,
    /// The walls measured at each band, lowest first (mm): for the fit.
    #[serde(default)]
    measured: Option<Vec<f64>>,
    /// The E per mm³ the print was written with (the page keeps it from
    /// the download): the fit uses it, never the printer's current value,
    /// so computing twice gives the same E (docs/CALIBRATION.md).
    #[serde(default)]
    written_e_per_mm3: Option<f64>,
}

/// The printer and calibration print an ask names.
fn calibration_of(
    ask: &CalibrationAsk,
) -> Result<(sweepclay_core::Printer, sweepclay_core::calibrate::Print), ApiError> {
    let printer = ask.printer.resolve()?;
    let params = ask.params.clone().unwrap_or_default();
    let print = sweepclay_core::calibrate::print(&printer, &params)?;
    Ok((printer, print))
}

fn read_ask(body: Result<Bytes, BytesRejection>) -> Result<CalibrationAsk, ApiError> {
    serde_json::from_slice(&bytes(body)?)
        .map_err(|e| ApiError::new(400, format!("calibration: {e}")))
}

/// The calibration print for a printer, checked, as a download.
pub(crate) async fn calibration_print(
    State(state): State<Shared>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let ask = read_ask(body)?;
    let gcode = state
        .pool
        .run(move |_| {
            let (printer, print) = calibration_of(&ask)?;
            let report =
                sweepclay_check::check(&print.gcode, &sweepclay_plan::printer_check(&printer));
            if !report.printable {
                return Err(ApiError::new(
                    422,
                    format!(
                        "the calibration print does not pass the check: {}",
                        report.failures.join("; ")
                    ),
                ));
            }
            Ok(print.gcode)
        })
        .await?;
    Ok((
        [
            (header::CONTENT_TYPE, "text/x-gcode; charset=utf-8"),
            (
                header::CONTENT_DISPOSITION,
                "attachment; filename=\"calibration.gcode\"",
            ),
        ],
        gcode,
    )
        .into_response())
}

/// What the fit found, for the printer dialog.
#[derive(serde::Serialize)]
pub(crate) struct Fitted {
    e_per_mm3: f64,
    /// The E the fit took the print to be written with.
    written_e_per_mm3: f64,
    per_band: Vec<f64>,
    spread: f64,
    /// Whether the bands agree well enough to use it.
    trusted: bool,
}

/// E per mm³ from the walls measured on the calibration print.
pub(crate) async fn calibration_fit(
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<Fitted>, ApiError> {
    let ask = read_ask(body)?;
    let (printer, print) = calibration_of(&ask)?;
    let measured = ask.measured.as_deref().ok_or_else(|| {
        ApiError::new(422, "give the wall measured at each band").with_key("measured")
    })?;
    let written = match ask.written_e_per_mm3 {
        Some(e) if e.is_finite() && e > 0.0 && e <= sweepclay_core::printer::MAX_E_PER_MM3 => e,
        Some(e) => {
            return Err(ApiError::new(
                422,
                format!(
                    "the E per mm³ the print was written with must be a positive number (got {e})"
                ),
            )
            .with_key("written_e_per_mm3"))
        }
        None => printer.e_per_mm3,
    };
    let f = sweepclay_core::calibrate::fit(&print.bands, measured, written)?;
    Ok(Json(Fitted {
        written_e_per_mm3: written,
        trusted: f.spread <= sweepclay_core::calibrate::TRUST_SPREAD,
        e_per_mm3: f.e_per_mm3,
        per_band: f.per_band,
        spread: f.spread,
    }))
}
