//! `https://` print hosts (docs/PRINTING.md, "https"): the certificates
//! this computer trusts, or the host's own — an OctoPi or a Klipper box
//! with a self-signed certificate — accepted by its SHA-256 fingerprint.
//!
//! A pinned certificate is taken on its fingerprint alone, whatever name
//! it carries (a self-signed one rarely names `octopi.local` or the
//! printer's IP address); its handshake signatures are still verified.
//! Every handshake notes the fingerprint the host showed, so a refusal can
//! say which certificate to accept.

use std::sync::{Arc, Mutex};

use rustls::client::danger::{HandshakeSignatureValid, ServerCertVerified, ServerCertVerifier};
use rustls::crypto::{verify_tls12_signature, verify_tls13_signature, CryptoProvider};
use rustls::pki_types::{CertificateDer, ServerName, UnixTime};
use rustls::{DigitallySignedStruct, SignatureScheme};
use sha2::{Digest, Sha256};

/// A certificate's SHA-256 fingerprint as browsers and `openssl x509
/// -fingerprint -sha256` show it: 32 upper-case hex pairs joined by `:`.
pub fn fingerprint(der: &[u8]) -> String {
    let d = Sha256::digest(der);
    d.iter()
        .map(|b| format!("{b:02X}"))
        .collect::<Vec<_>>()
        .join(":")
}

/// Reads a fingerprint as people copy it: 64 hex digits, with or without
/// `:` or spaces, any case, an optional `SHA256:`/`sha256 Fingerprint=`
/// label before it. The canonical form, or why not.
pub fn parse_fingerprint(s: &str) -> Result<String, String> {
    let body = s.rsplit(['=']).next().unwrap_or(s);
    let body = body
        .trim()
        .trim_start_matches("SHA256:")
        .trim_start_matches("sha256:");
    let hex: String = body
        .chars()
        .filter(|c| !matches!(c, ':' | ' ' | '-'))
        .collect();
    if hex.len() != 64 || !hex.chars().all(|c| c.is_ascii_hexdigit()) {
        return Err(format!(
            "a certificate's SHA-256 fingerprint is 64 hex digits, e.g. AB:CD:…; got {} character(s)",
            hex.len()
        ));
    }
    let up = hex.to_ascii_uppercase();
    Ok(up
        .as_bytes()
        .chunks(2)
        .map(|p| String::from_utf8_lossy(p).into_owned())
        .collect::<Vec<_>>()
        .join(":"))
}

/// Checks a host's certificate: the pinned one by fingerprint, any other
/// by the system's roots; notes the fingerprint it was shown.
#[derive(Debug)]
struct Verifier {
    pin: Option<String>,
    system: Option<Arc<dyn ServerCertVerifier>>,
    provider: Arc<CryptoProvider>,
    seen: Arc<Mutex<Option<String>>>,
}

impl ServerCertVerifier for Verifier {
    fn verify_server_cert(
        &self,
        end_entity: &CertificateDer<'_>,
        intermediates: &[CertificateDer<'_>],
        server_name: &ServerName<'_>,
        ocsp_response: &[u8],
        now: UnixTime,
    ) -> Result<ServerCertVerified, rustls::Error> {
        let fp = fingerprint(end_entity.as_ref());
        if let Ok(mut s) = self.seen.lock() {
            *s = Some(fp.clone());
        }
        match (&self.pin, &self.system) {
            (Some(pin), _) if *pin == fp => Ok(ServerCertVerified::assertion()),
            (Some(_), _) => Err(rustls::Error::General(
                "not the accepted certificate".into(),
            )),
            (None, Some(system)) => system.verify_server_cert(
                end_entity,
                intermediates,
                server_name,
                ocsp_response,
                now,
            ),
            (None, None) => Err(rustls::Error::General("no trusted roots".into())),
        }
    }

    fn verify_tls12_signature(
        &self,
        message: &[u8],
        cert: &CertificateDer<'_>,
        dss: &DigitallySignedStruct,
    ) -> Result<HandshakeSignatureValid, rustls::Error> {
        verify_tls12_signature(
            message,
            cert,
            dss,
            &self.provider.signature_verification_algorithms,
        )
    }

    fn verify_tls13_signature(
        &self,
        message: &[u8],
        cert: &CertificateDer<'_>,
        dss: &DigitallySignedStruct,
    ) -> Result<HandshakeSignatureValid, rustls::Error> {
        verify_tls13_signature(
            message,
            cert,
            dss,
            &self.provider.signature_verification_algorithms,
        )
    }

    fn supported_verify_schemes(&self) -> Vec<SignatureScheme> {
        self.provider
            .signature_verification_algorithms
            .supported_schemes()
    }
}

/// Makes ring this process's TLS provider, once: with TLS built in, the
/// HTTP client's plain `http://` clients ask the process for one too
/// (and panic without). Harmless when one is already installed.
pub fn install_provider() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // See host_tls on ring.
        #[allow(deprecated)]
        let _ = rustls::crypto::ring::default_provider().install_default();
    });
}

/// A TLS set-up for one host: the client configuration to hand to the
/// HTTP client, and where the last handshake's fingerprint is noted.
pub(crate) struct HostTls {
    pub(crate) config: rustls::ClientConfig,
    pub(crate) seen: Arc<Mutex<Option<String>>>,
}

/// The TLS set-up accepting `pin` (a canonical fingerprint), or the
/// system's roots when there is none. The system's verifier is optional:
/// a machine without root certificates can still reach a pinned host.
pub(crate) fn host_tls(pin: Option<String>) -> Result<HostTls, String> {
    // ring rather than aws-lc-rs (whose build wants cmake and a C
    // toolchain's extras): a printer's host offers no post-quantum key
    // exchange, which is all the deprecation is about.
    #[allow(deprecated)]
    let provider = Arc::new(rustls::crypto::ring::default_provider());
    let system: Option<Arc<dyn ServerCertVerifier>> = if pin.is_none() {
        rustls_platform_verifier::Verifier::new(provider.clone())
            .ok()
            .map(|v| Arc::new(v) as Arc<dyn ServerCertVerifier>)
    } else {
        None
    };
    let seen = Arc::new(Mutex::new(None));
    let verifier = Verifier {
        pin,
        system,
        provider: provider.clone(),
        seen: seen.clone(),
    };
    let config = rustls::ClientConfig::builder_with_provider(provider)
        .with_safe_default_protocol_versions()
        .map_err(|e| e.to_string())?
        .dangerous()
        .with_custom_certificate_verifier(Arc::new(verifier))
        .with_no_client_auth();
    Ok(HostTls { config, seen })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fingerprints_are_read_as_people_copy_them() {
        let canonical = fingerprint(b"clay");
        assert_eq!(canonical.len(), 32 * 3 - 1);
        let bare: String = canonical.replace(':', "").to_lowercase();
        assert_eq!(parse_fingerprint(&bare).unwrap(), canonical);
        let openssl = format!("sha256 Fingerprint={canonical}");
        assert_eq!(parse_fingerprint(&openssl).unwrap(), canonical);
        let e = parse_fingerprint("AB:CD").unwrap_err();
        assert!(e.contains("64 hex digits"), "{e}");
        assert!(parse_fingerprint(&"G".repeat(64)).is_err());
    }
}
