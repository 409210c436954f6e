//! What the server's print-host routes send where (docs/PRINTING.md, "What
//! the link sends where"), against stand-in hosts on loopback that record
//! every request they get: a host not saved on this machine is never
//! reached, `$SWEEPCLAY_HOST_KEY` never leaves the server, a redirect is
//! not followed (so the key stays with its host), an endless answer is cut
//! off, and saves at once lose no host.
//!
//! Its own test binary: it sets the process's environment.

use axum::body::Body;
use axum::http::{HeaderMap, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use serde_json::{json, Value};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use sweepclay_web::api::Limits;

mod common;
use common::{post, server};

/// Every request a stand-in got: its path and its `X-Api-Key`, if any.
type Log = Arc<Mutex<Vec<(String, Option<String>)>>>;

/// How a stand-in OctoPrint answers `GET /api/job`.
#[derive(Clone)]
enum Answer {
    /// As OctoPrint does.
    Job,
    /// 302 to this address.
    Redirect(String),
    /// 200 with a body that never ends.
    Endless,
    /// 403, as OctoPrint answers a wrong key.
    Refuse,
}

async fn stand_in(answer: Answer) -> (String, Log) {
    let log: Log = Arc::default();
    let kept = log.clone();
    let app = Router::new().route(
        "/api/job",
        get(move |h: HeaderMap| {
            let answer = answer.clone();
            let log = kept.clone();
            async move {
                let key = h.get("x-api-key").map(|k| k.to_str().unwrap().to_string());
                log.lock().unwrap().push(("/api/job".into(), key));
                match answer {
                    Answer::Job => axum::Json(json!({
                        "state": "Operational",
                        "job": {"file": {"name": null}},
                        "progress": {"completion": null}
                    }))
                    .into_response(),
                    Answer::Redirect(to) => Response::builder()
                        .status(StatusCode::FOUND)
                        .header("location", format!("{to}/api/job?apikey=x"))
                        .body(Body::empty())
                        .unwrap(),
                    Answer::Refuse => StatusCode::FORBIDDEN.into_response(),
                    Answer::Endless => {
                        let chunk = axum::body::Bytes::from(vec![b' '; 64 << 10]);
                        let s = futures_stream(chunk);
                        Response::builder()
                            .status(StatusCode::OK)
                            .header("content-type", "application/json")
                            .body(Body::from_stream(s))
                            .unwrap()
                    }
                }
            }
        }),
    );
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    tokio::spawn(async move { axum::serve(listener, app).await.unwrap() });
    (format!("http://{addr}"), log)
}

/// An endless stream of `chunk`s.
fn futures_stream(
    chunk: axum::body::Bytes,
) -> impl futures_core::Stream<Item = Result<axum::body::Bytes, std::io::Error>> {
    struct Endless(axum::body::Bytes);
    impl futures_core::Stream for Endless {
        type Item = Result<axum::body::Bytes, std::io::Error>;
        fn poll_next(
            self: std::pin::Pin<&mut Self>,
            _: &mut std::task::Context<'_>,
        ) -> std::task::Poll<Option<Self::Item>> {
            std::task::Poll::Ready(Some(Ok(self.0.clone())))
        }
    }
    Endless(chunk)
}

async fn status(base: &str, url: &str) -> (u16, Value) {
    let r = post(
        &format!("{base}/api/host/status"),
        json!({"kind": "octoprint", "url": url}).to_string(),
    )
    .await;
    (r.status().as_u16(), r.json().await.unwrap())
}

async fn save(base: &str, body: Value) {
    let r = post(&format!("{base}/api/host/key"), body.to_string()).await;
    assert_eq!(r.status(), 200, "{:?}", r.text().await);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_server_talks_only_to_saved_hosts_and_keys_stay_with_theirs() {
    let config = tempfile::tempdir().unwrap();
    std::env::set_var("SWEEPCLAY_CONFIG_DIR", config.path());
    // A server started with a key in its environment: before, it sent it
    // to whatever address a request named.
    std::env::set_var("SWEEPCLAY_HOST_KEY", "ENV-SECRET");
    let base = server(Limits::default()).await;
    let (host, log) = stand_in(Answer::Job).await;

    // Not saved: refused, and the host never hears of it.
    let (code, v) = status(&base, &host).await;
    assert_eq!(code, 403, "{v}");
    assert!(
        v["error"].as_str().unwrap().contains("not one saved"),
        "{v}"
    );
    assert_eq!(v["key"], "host.url");
    assert!(log.lock().unwrap().is_empty());
    // Nor through /api/send with a design naming it.
    let mut d: Value =
        serde_json::from_str(sweepclay_core::examples::example("cup").unwrap()).unwrap();
    let mut printer =
        serde_json::to_value(sweepclay_core::printer::Printer::preset("cerambot-mini").unwrap())
            .unwrap();
    printer["host"] = json!({"kind": "octoprint", "url": host});
    d["printer"] = printer;
    let r = post(&format!("{base}/api/send"), d.to_string()).await;
    assert_eq!(r.status(), 403);
    assert!(log.lock().unwrap().is_empty());

    // Saved without a key: reached, and the environment's key is not sent.
    save(&base, json!({"url": format!("{host}/")})).await;
    let (code, v) = status(&base, &host).await;
    assert_eq!(code, 200, "{v}");
    assert_eq!(v["state"], "Operational");
    assert_eq!(log.lock().unwrap().as_slice(), [("/api/job".into(), None)]);

    // With its key: the key goes there, and an empty key keeps it.
    save(&base, json!({"url": host, "key": "K1"})).await;
    save(&base, json!({"url": host, "key": ""})).await;
    status(&base, &host).await;
    assert_eq!(log.lock().unwrap()[1].1.as_deref(), Some("K1"));

    // A saved host that redirects elsewhere: not followed, key kept home.
    let (elsewhere, elsewhere_log) = stand_in(Answer::Job).await;
    let (moved, moved_log) = stand_in(Answer::Redirect(elsewhere.clone())).await;
    save(&base, json!({"url": moved, "key": "K2"})).await;
    let (code, v) = status(&base, &moved).await;
    assert_eq!(code, 502, "{v}");
    let e = v["error"].as_str().unwrap();
    assert!(e.contains("redirect") && e.contains(&elsewhere), "{e}");
    assert!(!e.contains("apikey"), "{e}");
    assert_eq!(moved_log.lock().unwrap().len(), 1);
    assert!(elsewhere_log.lock().unwrap().is_empty());

    // A host whose answer never ends: cut off at the cap, the server up.
    let (endless, _) = stand_in(Answer::Endless).await;
    save(&base, json!({"url": endless})).await;
    let t = Instant::now();
    let (code, v) = status(&base, &endless).await;
    assert_eq!(code, 502, "{v}");
    assert!(
        v["error"].as_str().unwrap().contains("larger than 4 MiB"),
        "{v}"
    );
    assert!(t.elapsed() < Duration::from_secs(15), "{:?}", t.elapsed());
    let (code, _) = status(&base, &host).await;
    assert_eq!(code, 200, "the server still answers");

    // Forgotten: refused again.
    save(&base, json!({"url": host, "forget": true})).await;
    assert_eq!(status(&base, &host).await.0, 403);

    // Fifty saves at once keep fifty hosts (before: 3 of 50).
    let saves = (0..50).map(|i| {
        let base = base.clone();
        tokio::spawn(async move {
            save(
                &base,
                json!({"url": format!("http://printer{i}.local"), "key": "K"}),
            )
            .await
        })
    });
    for s in saves.collect::<Vec<_>>() {
        s.await.unwrap();
    }
    let keys = sweepclay_link::keys::read(&sweepclay_link::keys::path_in(config.path())).unwrap();
    assert_eq!(
        keys.keys()
            .filter(|k| k.starts_with("http://printer"))
            .count(),
        50
    );
    // The file keeps its keys to its owner.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let p = sweepclay_link::keys::path_in(config.path());
        assert_eq!(
            std::fs::metadata(p).unwrap().permissions().mode() & 0o077,
            0
        );
    }
    // Issue 59, point 5: a wrong key is said in the page's words, with no
    // command line and no backticks.
    let (refusing, _) = stand_in(Answer::Refuse).await;
    save(&base, json!({"url": refusing, "key": "wrong"})).await;
    let (code, v) = status(&base, &refusing).await;
    assert_eq!(code, 502, "{v}");
    let said = v["error"].as_str().unwrap();
    assert!(said.starts_with("OctoPrint refused the API key"), "{said}");
    assert!(said.contains("Edit printer"), "{said}");
    assert!(!said.contains('`') && !said.contains("--"), "{said}");
}
