//! `https://` hosts: the real OctoPrint on loopback behind a TLS front
//! with a self-signed certificate, as an OctoPi's HAProxy serves it. The
//! link refuses the certificate until the user accepts its fingerprint,
//! then sends and prints through it; another certificate is refused.

mod hosts;

use std::sync::Arc;
use sweepclay_link::tls::fingerprint;
use sweepclay_link::{Kind, Link, LinkError};
use tokio::net::{TcpListener, TcpStream};
use tokio_rustls::rustls;

/// A self-signed certificate for `localhost` and 127.0.0.1: its DER and
/// key.
fn self_signed() -> (Vec<u8>, Vec<u8>) {
    let c =
        rcgen::generate_simple_self_signed(vec!["localhost".into(), "127.0.0.1".into()]).unwrap();
    (c.cert.der().to_vec(), c.signing_key.serialize_der())
}

/// A TLS front on a free loopback port passing every connection on to
/// `upstream` (host:port); its `https://` address.
async fn tls_front(upstream: String, cert: Vec<u8>, key: Vec<u8>) -> String {
    use rustls::pki_types::{CertificateDer, PrivateKeyDer, PrivatePkcs8KeyDer};
    // ring, as the link itself uses (src/tls.rs).
    #[allow(deprecated)]
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let config = rustls::ServerConfig::builder_with_provider(provider)
        .with_safe_default_protocol_versions()
        .unwrap()
        .with_no_client_auth()
        .with_single_cert(
            vec![CertificateDer::from(cert)],
            PrivateKeyDer::Pkcs8(PrivatePkcs8KeyDer::from(key)),
        )
        .unwrap();
    let acceptor = tokio_rustls::TlsAcceptor::from(Arc::new(config));
    let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let port = listener.local_addr().unwrap().port();
    tokio::spawn(async move {
        loop {
            let Ok((tcp, _)) = listener.accept().await else {
                return;
            };
            let (acceptor, upstream) = (acceptor.clone(), upstream.clone());
            tokio::spawn(async move {
                // A refused handshake is the client's business.
                let Ok(mut tls) = acceptor.accept(tcp).await else {
                    return;
                };
                let Ok(mut up) = TcpStream::connect(&upstream).await else {
                    return;
                };
                let _ = tokio::io::copy_bidirectional(&mut tls, &mut up).await;
            });
        }
    });
    format!("https://127.0.0.1:{port}")
}

/// The certificate refusal `link` answers a status with: the fingerprint
/// it names and why.
async fn refusal(link: &Link) -> (String, String) {
    match link.status().await.unwrap_err() {
        LinkError::Certificate { sha256, why, .. } => (sha256, why),
        e => panic!("expected a certificate refusal, got {e}"),
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn an_https_octoprint_is_reached_once_its_certificate_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let Some(server) = hosts::octoprint(&dir.path().join("octoprint")) else {
        return;
    };
    let upstream = server
        .url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    let (cert, key) = self_signed();
    let fp = fingerprint(&cert);
    let url = tls_front(upstream, cert, key).await;
    let link = |cert: Option<&str>| {
        Link::with_certificate(Kind::OctoPrint, &url, Some(server.key.clone()), cert).unwrap()
    };

    // Not trusted by this computer: refused, naming the fingerprint.
    let (sha256, why) = refusal(&link(None)).await;
    assert_eq!(sha256, fp);
    assert!(why.contains("does not trust"), "{why}");

    // Accepted by its fingerprint (as copied: lower case, no colons): the
    // file goes up, prints and ends.
    let copied = fp.replace(':', "").to_lowercase();
    let accepted = link(Some(&copied));
    let stored = accepted
        .upload(
            "tls",
            b"G21\nG90\nM82\nG92 E0\nG1 X110 Y100 Z1 E1 F1200\n".to_vec(),
        )
        .await
        .unwrap();
    assert!(accepted.files().await.unwrap().contains(&stored));
    accepted.start(&stored).await.unwrap();
    let mut done = false;
    for _ in 0..300 {
        if !accepted.status().await.unwrap().printing {
            done = true;
            break;
        }
        tokio::time::sleep(std::time::Duration::from_millis(200)).await;
    }
    assert!(done, "the print did not end in 60 s");

    // Another certificate in its place: refused, both named.
    let (other, _) = self_signed();
    let wrong = fingerprint(&other);
    let (sha256, why) = refusal(&link(Some(&wrong))).await;
    assert_eq!(sha256, fp);
    assert!(why.contains(&wrong), "{why}");
}

#[test]
fn a_malformed_fingerprint_is_refused_by_name() {
    let e = Link::with_certificate(Kind::OctoPrint, "https://octopi.local", None, Some("AB:CD"))
        .unwrap_err();
    assert!(e.to_string().contains("64 hex digits"), "{e}");
}
