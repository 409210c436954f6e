//! # sweepclay-web
//!
//! The interactive modeler of the paper (Zhong et al. 2020, §3 and Fig. 2):
//! `sweepclay serve` starts a local web server whose page lets a designer
//! draw the two profile curves, the trajectory and the interpolation curve,
//! and see at once the surface, the toolpath and the statistics of what
//! will print. It is a thin shell over the library: the same design file
//! (docs/FORMATS.md), the same pipeline (`sweepclay-core`) and the same
//! checker (`sweepclay-check`).
//!
//! | route | body | answer |
//! |---|---|---|
//! | `GET /` | | the page (assets are built into the binary) |
//! | `GET /api/meta` | | presets, default parameters, examples, limits |
//! | `POST /api/slice` | design JSON | [`api::SliceView`]: the correction loop's last round (the path the G-code prints): surface samples, path with widths, stats, corrections, warnings, the verdict (`?format=binary`: [`api::SliceView::to_binary`], what the page uses) |
//! | `POST /api/verify` | design JSON | [`api::Verdict`]: the checker's verdict on its G-code |
//! | `POST /api/gcode` | design JSON | the verified G-code, or 422 with the failures and where they are |
//! | `POST /api/stl` | design JSON | binary STL of the surface thickened to the bead width |
//! | `POST /api/check` | G-code text | the checker's report on any G-code (query: `printer`; default: the header's, else `generic`) |
//! | `POST /api/import/svg`, `/api/import/csv` | file text | trajectory points |
//!
//! Errors are JSON `{"error": "...", "key": "..."}` with a 4xx status.
//! Bodies are capped ([`DESIGN_BODY_LIMIT`], [`GCODE_BODY_LIMIT`]) and so is
//! a design's estimated sample count ([`api::Limits`]).

pub mod api;
pub mod conn;
pub mod error;
pub mod guard;
mod printing;

use api::{ApiError, Limits};
use axum::body::Bytes;
use axum::extract::rejection::BytesRejection;
use axum::extract::{DefaultBodyLimit, Path, Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use guard::{Cancel, Stopped};
use serde::Deserialize;
use std::collections::HashMap;
use std::sync::Arc;
use sweepclay_check::CheckConfig;
use sweepclay_core::printer::PRESETS;
use sweepclay_core::{examples, Params, Printer};

/// Largest design or imported file accepted (bytes).
pub const DESIGN_BODY_LIMIT: usize = 4 << 20;
/// Largest mesh `/api/mesh` accepts (bytes): a binary STL of two
/// million triangles.
pub const MESH_BODY_LIMIT: usize = 100 << 20;
/// Largest G-code file `/api/check` accepts (bytes).
pub const GCODE_BODY_LIMIT: usize = 64 << 20;

/// The page's files, built into the binary: (path, content type, text).
pub const ASSETS: &[(&str, &str, &str)] = &[
    (
        "index.html",
        "text/html; charset=utf-8",
        include_str!("../assets/index.html"),
    ),
    (
        "style.css",
        "text/css; charset=utf-8",
        include_str!("../assets/style.css"),
    ),
    (
        "app.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/app.js"),
    ),
    (
        "editor.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/editor.js"),
    ),
    (
        "view3d.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/view3d.js"),
    ),
    (
        "bspline.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/bspline.js"),
    ),
    (
        "frame.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/frame.js"),
    ),
    (
        "mesh.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/mesh.js"),
    ),
    (
        "io.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/io.js"),
    ),
    (
        "printer-dialog.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/printer-dialog.js"),
    ),
    (
        "status.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/status.js"),
    ),
    (
        "params.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/params.js"),
    ),
    (
        "params-panel.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/params-panel.js"),
    ),
    (
        "numbers.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/numbers.js"),
    ),
    (
        "surface-panel.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/surface-panel.js"),
    ),
    (
        "store.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/store.js"),
    ),
    (
        "curves3d.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/curves3d.js"),
    ),
    (
        "shapes.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/shapes.js"),
    ),
    (
        "editors-panel.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/editors-panel.js"),
    ),
    (
        "pots-panel.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/pots-panel.js"),
    ),
    (
        "files.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/files.js"),
    ),
    (
        "transform-panel.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/transform-panel.js"),
    ),
    (
        "slice-worker.js",
        "text/javascript; charset=utf-8",
        include_str!("../assets/slice-worker.js"),
    ),
];

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let status = StatusCode::from_u16(self.status).unwrap_or(StatusCode::BAD_REQUEST);
        let retry = self.retry_after;
        let mut res = (status, Json(self)).into_response();
        if let Some(secs) = retry {
            res.headers_mut()
                .insert(header::RETRY_AFTER, axum::http::HeaderValue::from(secs));
        }
        res
    }
}

/// What every handler shares: the limits and the pool of workers.
pub(crate) struct AppState {
    limits: Limits,
    pool: guard::Pool,
    /// Stage 1's recent outputs: an edit that changes only the printer,
    /// speeds or flow is not resampled (docs/ARCHITECTURE.md, "Stages").
    samples: sweepclay_plan::Samples,
}

pub(crate) type Shared = Arc<AppState>;

/// The modeler's routes, with the given limits.
pub fn router(limits: Limits) -> Router {
    let design_routes = Router::new()
        .route("/api/slice", post(slice))
        .route("/api/verify", post(verify_design))
        .route("/api/gcode", post(gcode))
        .route("/api/stl", post(stl))
        .route("/api/import/{format}", post(import))
        .route("/api/transform", post(transform))
        .route("/api/send", post(printing::send))
        .route("/api/host/status", post(printing::host_status))
        .route("/api/host/job", post(printing::host_job))
        .route("/api/host/key", post(printing::host_key))
        .route("/api/calibrate", post(printing::calibration_print))
        .route("/api/calibrate/fit", post(printing::calibration_fit))
        .layer(DefaultBodyLimit::max(DESIGN_BODY_LIMIT));
    let check_route = Router::new()
        .route("/api/check", post(check))
        .layer(DefaultBodyLimit::max(GCODE_BODY_LIMIT));
    let mesh_route = Router::new()
        .route("/api/mesh", post(mesh))
        .layer(DefaultBodyLimit::max(MESH_BODY_LIMIT));
    let who = Arc::new(guard::Admission::of(&limits));
    let guard = axum::middleware::from_fn(move |req: axum::extract::Request, next| {
        let body_limit = match req.uri().path() {
            "/api/check" => GCODE_BODY_LIMIT,
            "/api/mesh" => MESH_BODY_LIMIT,
            _ => DESIGN_BODY_LIMIT,
        };
        guard::same_origin(who.clone(), body_limit, req, next)
    });
    let state = Arc::new(AppState {
        pool: guard::Pool::new(&limits),
        limits,
        samples: sweepclay_plan::Samples::new(),
    });
    Router::new()
        .route("/", get(|| asset(Path("index.html".into()))))
        .route("/assets/{name}", get(asset))
        .route("/api/meta", get(meta))
        .merge(design_routes)
        .merge(check_route)
        .merge(mesh_route)
        .fallback(|| async { ApiError::new(404, "no such page or API route") })
        .method_not_allowed_fallback(|| async {
            ApiError::new(405, "this route does not take that method")
        })
        .layer(guard)
        .with_state(state)
}

async fn asset(Path(name): Path<String>) -> Response {
    match ASSETS.iter().find(|(n, _, _)| *n == name) {
        Some((_, ty, text)) => (
            [
                (header::CONTENT_TYPE, *ty),
                (header::CACHE_CONTROL, "no-cache"),
            ],
            *text,
        )
            .into_response(),
        None => ApiError::new(404, format!("no asset `{name}`")).into_response(),
    }
}

async fn meta(State(limits): State<Shared>) -> Response {
    let presets: Vec<Printer> = PRESETS.iter().filter_map(|n| Printer::preset(n)).collect();
    let examples: Vec<serde_json::Value> = examples::EXAMPLES
        .iter()
        .filter_map(|(file, text)| {
            let design: serde_json::Value = serde_json::from_str(text).ok()?;
            Some(serde_json::json!({ "name": file.trim_end_matches(".json"), "design": design }))
        })
        .collect();
    Json(serde_json::json!({
        "version": env!("CARGO_PKG_VERSION"),
        "presets": presets,
        "params": Params::default(),
        "examples": examples,
        "max_samples": limits.limits.max_samples,
        "max_floor_layers": sweepclay_core::design::MAX_FLOOR_LAYERS,
    }))
    .into_response()
}

/// The request body as text, with size and encoding errors as JSON.
pub(crate) fn bytes(body: Result<Bytes, BytesRejection>) -> Result<Bytes, ApiError> {
    body.map_err(|e| {
        let status = e.status().as_u16();
        if status == 413 {
            ApiError::new(413, "request body too large".to_string())
        } else {
            ApiError::new(status, e.body_text())
        }
    })
}

fn text(body: Result<Bytes, BytesRejection>) -> Result<String, ApiError> {
    String::from_utf8(bytes(body)?.to_vec())
        .map_err(|e| ApiError::new(400, format!("the body is not UTF-8 text: {e}")))
}

pub(crate) async fn with_design<T: Send + 'static>(
    limits: Shared,
    body: Result<Bytes, BytesRejection>,
    f: impl FnOnce(sweepclay_plan::Job, &Cancel) -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    let text = text(body)?;
    let state = limits.clone();
    state
        .pool
        .run(move |cancel| {
            let job = api::parse_design(&text, &limits.limits)?.with_samples(&limits.samples);
            f(job, cancel)
        })
        .await
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SliceQuery {
    /// `json` (default) or `binary` ([`api::SliceView::to_binary`]).
    format: Option<String>,
}

async fn slice(
    State(limits): State<Shared>,
    query: Result<Query<SliceQuery>, axum::extract::rejection::QueryRejection>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    let Query(q) = query.map_err(|e| ApiError::new(400, e.body_text()))?;
    let binary = match q.format.as_deref() {
        None | Some("json") => false,
        Some("binary") => true,
        Some(other) => {
            return Err(
                ApiError::new(400, format!("format: `{other}` is not json or binary"))
                    .with_key("format"),
            )
        }
    };
    let view = with_design(limits, body, |d, c| api::slice_view(&d, c)).await?;
    Ok(if binary {
        (
            [(header::CONTENT_TYPE, "application/octet-stream")],
            view.to_binary(),
        )
            .into_response()
    } else {
        Json(view).into_response()
    })
}

async fn verify_design(
    State(limits): State<Shared>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<api::Verdict>, ApiError> {
    with_design(limits, body, |d, c| {
        Ok(api::verdict(&api::verified(&d, c)?))
    })
    .await
    .map(Json)
}

/// A file download: the design's name (made safe) with `ext`.
fn attachment(
    design: &sweepclay_core::Design,
    ext: &str,
    content_type: &'static str,
    body: impl Into<axum::body::Body>,
) -> Response {
    let stem: String = design
        .name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stem = match stem.trim_matches('_') {
        "" => "sweepclay",
        s => s,
    };
    // The name itself, Unicode kept, as RFC 6266's `filename*` (an ASCII
    // `filename` for old clients): only what no file system takes is
    // replaced, as the page does.
    let unsafe_char = |c: char| "/\\:*?\"<>|".contains(c) || c.is_control();
    let full: String = design
        .name
        .chars()
        .map(|c| if unsafe_char(c) { '_' } else { c })
        .collect();
    let full = full.trim_matches(|c: char| c.is_whitespace() || c == '.');
    let full = if full.is_empty() { stem } else { full };
    let encoded: String = format!("{full}.{ext}")
        .bytes()
        .map(|b| {
            if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
                (b as char).to_string()
            } else {
                format!("%{b:02X}")
            }
        })
        .collect();
    (
        [
            (header::CONTENT_TYPE, content_type.to_string()),
            (
                header::CONTENT_DISPOSITION,
                format!("attachment; filename=\"{stem}.{ext}\"; filename*=UTF-8''{encoded}"),
            ),
        ],
        body.into(),
    )
        .into_response()
}

async fn gcode(
    State(limits): State<Shared>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    with_design(limits, body, |d, c| {
        let text = api::gcode(&d, c)?;
        Ok(attachment(
            d.design(),
            "gcode",
            "text/x-gcode; charset=utf-8",
            text,
        ))
    })
    .await
}

async fn stl(
    State(limits): State<Shared>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Response, ApiError> {
    with_design(limits, body, |d, c| {
        let bytes = api::stl(&d, c)?;
        Ok(attachment(d.design(), "stl", "model/stl", bytes))
    })
    .await
}

async fn import(
    State(state): State<Shared>,
    Path(format): Path<String>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<api::Imported>, ApiError> {
    let text = text(body)?;
    state
        .pool
        .run(move |_| api::import(&format, &text))
        .await
        .map(Json)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransformQuery {
    /// How many times as large (default 1).
    scale: Option<f64>,
    /// Degrees counter-clockwise about o (default 0).
    turn: Option<f64>,
}

/// A design scaled and turned about o (`Design::transformed`): the page
/// sizes and turns a mesh-backed design without a copy of the library.
async fn transform(
    State(state): State<Shared>,
    query: Result<Query<TransformQuery>, axum::extract::rejection::QueryRejection>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<serde_json::Value>, ApiError> {
    let Query(q) = query.map_err(|e| ApiError::new(400, e.body_text()))?;
    let text = text(body)?;
    state
        .pool
        .run(move |_| {
            let d = sweepclay_core::Design::from_json(&text)?
                .transformed(q.scale.unwrap_or(1.0), q.turn.unwrap_or(0.0))?;
            serde_json::from_str(&d.to_json())
                .map_err(|e| ApiError::new(500, format!("the transformed design: {e}")))
        })
        .await
        .map(Json)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshQuery {
    /// The file's name: its extension says STL or OBJ.
    name: String,
    /// The axis that points up: x, y or z (default).
    up: Option<String>,
}

async fn mesh(
    State(state): State<Shared>,
    query: Result<Query<MeshQuery>, axum::extract::rejection::QueryRejection>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<api::MeshImport>, ApiError> {
    let Query(q) = query.map_err(|e| ApiError::new(400, e.body_text()))?;
    let up = match q.up.as_deref() {
        None | Some("z") => 2,
        Some("y") => 1,
        Some("x") => 0,
        Some(other) => {
            return Err(
                ApiError::new(400, format!("up: `{other}` is not x, y or z")).with_key("up"),
            )
        }
    };
    let bytes = bytes(body)?;
    state
        .pool
        .run(move |_| api::import_mesh(&q.name, &bytes, up))
        .await
        .map(Json)
}

#[derive(Deserialize)]
struct CheckQuery {
    printer: Option<String>,
    #[serde(flatten)]
    rest: HashMap<String, String>,
}

async fn check(
    State(state): State<Shared>,
    Query(q): Query<CheckQuery>,
    body: Result<Bytes, BytesRejection>,
) -> Result<Json<sweepclay_check::Report>, ApiError> {
    if let Some(k) = q.rest.keys().next() {
        return Err(ApiError::new(
            400,
            format!("unknown query key `{k}` (only `printer`)"),
        ));
    }
    let printer = match &q.printer {
        Some(name) => Some(Printer::preset(name).ok_or_else(|| {
            ApiError::new(
                422,
                format!("printer: `{name}` is not a preset ({})", PRESETS.join(", ")),
            )
            .with_key("printer")
        })?),
        None => None,
    };
    // Bytes, not text: a comment in Latin-1 is no reason to refuse a
    // file the CLI checks (the checker reads G-code as bytes).
    let text = bytes(body)?;
    state
        .pool
        .run(move |cancel| {
            // Without `printer`, a sweepclay file is checked for the printer
            // its header names, any other for `generic` (as the CLI does).
            let cfg = match printer {
                Some(p) => sweepclay_plan::printer_check(&p),
                None => {
                    // The header is read as the CLI reads it (its first
                    // 64 KB, bytes that are not UTF-8 replaced), and its
                    // values validated exactly as flags are.
                    let head = String::from_utf8_lossy(&text[..text.len().min(1 << 16)]);
                    sweepclay_check::header::config_from_header(&head, &CheckConfig::default())
                        .unwrap_or_else(|| CheckConfig {
                            printer: "generic (assumed: pass ?printer=)".into(),
                            ..CheckConfig::default()
                        })
                }
            };
            cfg.validate().map_err(|e| {
                ApiError::new(
                    422,
                    format!("the file's header: `{}`: {}", e.field, e.reason),
                )
                .with_key(e.field)
            })?;
            let read = std::io::BufReader::with_capacity(
                1 << 16,
                guard::CancelReader(&text[..], cancel.clone()),
            );
            sweepclay_check::check_reader(read, &cfg).map_err(|e| cancel.io_error("checking", e))
        })
        .await
        .map(Json)
}

/// Serves the modeler on `listener` until Ctrl+C, within the limits'
/// connection cap and idle timeout ([`conn`]).
pub async fn run(listener: tokio::net::TcpListener, limits: Limits) -> std::io::Result<()> {
    let listener = conn::Capped::new(listener, limits.connections);
    axum::serve(listener, router(limits))
        .with_graceful_shutdown(async {
            let _ = tokio::signal::ctrl_c().await;
        })
        .await
}
