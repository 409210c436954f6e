//! Helpers shared by the tests over a real server.

use sweepclay_web::api::Limits;

/// Starts the server on 127.0.0.1:0 in the background; returns its base URL.
pub async fn server(limits: Limits) -> String {
    // The tests' own HTTP clients share the link's TLS provider.
    sweepclay_link::tls::install_provider();
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    tokio::spawn(async move {
        axum::serve(listener, sweepclay_web::router(limits))
            .await
            .unwrap()
    });
    format!("http://{addr}")
}

/// POSTs `body` as the page does (`application/json`; the work routes
/// take nothing a cross-origin page could send without asking).
pub async fn post(url: &str, body: impl Into<reqwest::Body>) -> reqwest::Response {
    reqwest::Client::new()
        .post(url)
        .header("content-type", "application/json")
        .body(body)
        .send()
        .await
        .unwrap()
}
