//! The printer link: sends a checked G-code file to the machine's print
//! host and follows the print (docs/PRINTING.md).
//!
//! Three hosts, the ones clay printers sit behind: OctoPrint (Marlin
//! machines such as Eazao's on a Raspberry Pi), Klipper's Moonraker, and
//! RepRapFirmware's own web server (Duet boards). Each speaks its published
//! HTTP API; [`Link`] gives the same four verbs over all three: upload,
//! start, status and list. Every failure a potter can meet is one
//! [`LinkError`] with one plain sentence: a wrong key, an unreachable host,
//! a full card, a printer busy printing or not connected.
//!
//! This crate knows nothing of the pipeline or the checker: the CLI and the
//! server check a file before they hand it here. Secrets (API keys,
//! passwords) never live in a printer profile or a design: [`keys`] keeps
//! them in the user's configuration directory.

pub mod keys;
mod moonraker;
mod octoprint;
mod reprap;
pub mod tls;

use serde::Serialize;
use std::fmt;
use std::time::Duration;

/// Which print host a printer sits behind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// OctoPrint (`/api/files/local`, `X-Api-Key`).
    OctoPrint,
    /// Klipper's Moonraker (`/server/files/upload`, optional `X-Api-Key`).
    Moonraker,
    /// RepRapFirmware's web server in standalone mode (`rr_connect`,
    /// `rr_upload`, `M32`).
    RepRap,
}

impl Kind {
    /// The name a printer profile uses for it.
    pub fn name(self) -> &'static str {
        match self {
            Kind::OctoPrint => "octoprint",
            Kind::Moonraker => "moonraker",
            Kind::RepRap => "reprap",
        }
    }

    /// What the potter calls it, in messages.
    fn title(self) -> &'static str {
        match self {
            Kind::OctoPrint => "OctoPrint",
            Kind::Moonraker => "Moonraker",
            Kind::RepRap => "the Duet (RepRapFirmware)",
        }
    }

    /// The kind a profile names, if it is one.
    pub fn from_name(name: &str) -> Option<Kind> {
        [Kind::OctoPrint, Kind::Moonraker, Kind::RepRap]
            .into_iter()
            .find(|k| k.name() == name)
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why talking to a print host failed, each in one plain sentence.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LinkError {
    /// The address is not one the link can use.
    #[error("print host address `{url}`: {why}")]
    Address {
        /// The address as given.
        url: String,
        /// What is wrong with it.
        why: String,
    },
    /// Nothing answered (off, another network, a wrong address or port).
    #[error("cannot reach {host} at {url}: {why}; is it switched on and on this network, and is the address right?")]
    Unreachable {
        /// The host's name in messages.
        host: &'static str,
        /// Its address.
        url: String,
        /// What the network said.
        why: String,
    },
    /// The key or password was refused.
    #[error("{host} refused the {what}: copy it again from {host}'s settings and save it with sweepclay send --save-key")]
    WrongKey {
        /// The host's name in messages.
        host: &'static str,
        /// "API key" or "password".
        what: &'static str,
    },
    /// The host has no room for the file.
    #[error("{host} has no room for the file: delete old prints from its storage (SD card) and send again")]
    Full {
        /// The host's name in messages.
        host: &'static str,
    },
    /// The printer is printing (or paused in a print).
    #[error("the printer is busy printing `{file}`: wait for it to finish, or stop it on the printer, then start the new file")]
    Busy {
        /// The file it is printing, as the host names it.
        file: String,
    },
    /// The host runs but the printer is not connected to it.
    #[error("{host} is running but the printer is not connected to it ({state}): connect the printer there, then start the file")]
    NotConnected {
        /// The host's name in messages.
        host: &'static str,
        /// The state the host reports.
        state: String,
    },
    /// Any other refusal, with the host's own words.
    #[error("{host} refused: HTTP {status}: {message}")]
    Refused {
        /// The host's name in messages.
        host: &'static str,
        /// The HTTP status.
        status: u16,
        /// The host's message, shortened.
        message: String,
    },
    /// The host answered with a redirect. None is followed: the key would
    /// go with it to wherever the redirect points (docs/PRINTING.md,
    /// "What the link sends where").
    #[error("{host} at {url} answered with a redirect (HTTP {status}) to {to}; sweepclay follows no redirect, so the key never leaves the address you saved: if that is your printer's address, put it in the printer profile")]
    Redirect {
        /// The host's name in messages.
        host: &'static str,
        /// Its address.
        url: String,
        /// The HTTP status.
        status: u16,
        /// Where it pointed, without any query (which may carry a secret).
        to: String,
    },
    /// An `https://` host showed a certificate this computer does not
    /// trust, or not the one accepted for it (docs/PRINTING.md, "https").
    #[error("{host} at {url} showed a certificate {why}. Its SHA-256 fingerprint is {sha256}: if that is your printer's (its settings page or `openssl x509 -fingerprint -sha256` on it shows the same), accept it as the printer's certificate")]
    Certificate {
        /// The host's name in messages.
        host: &'static str,
        /// Its address.
        url: String,
        /// What was wrong with it.
        why: String,
        /// The fingerprint of the certificate the host showed.
        sha256: String,
    },
    /// An answer that is not the host's API (another program on the port).
    #[error("{host} at {url} answered something that is not its API ({why}): is the kind right?")]
    BadAnswer {
        /// The host's name in messages.
        host: &'static str,
        /// Its address.
        url: String,
        /// What was wrong.
        why: String,
    },
}

/// What to do with the print under way.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum JobAction {
    /// Stop where it is, to go on later.
    Pause,
    /// Go on after a pause.
    Resume,
    /// Stop for good.
    Cancel,
}

impl JobAction {
    /// The word for messages.
    pub fn name(self) -> &'static str {
        match self {
            JobAction::Pause => "pause",
            JobAction::Resume => "resume",
            JobAction::Cancel => "cancel",
        }
    }
}

/// What the host says the printer is doing.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Status {
    /// The state in the host's own word ("Printing", "standby",
    /// "processing", …).
    pub state: String,
    /// Whether a print is under way (printing, paused or finishing).
    pub printing: bool,
    /// Whether the printer is connected and ready or busy (not offline or
    /// in error).
    pub connected: bool,
    /// The file selected or printing, if any.
    pub file: Option<String>,
    /// How far through the file, 0 to 1, where the host reports it.
    pub progress: Option<f64>,
}

/// How long a connection may take to open.
const CONNECT: Duration = Duration::from_secs(5);
/// How long a short request (status, start, list) may take.
const SHORT: Duration = Duration::from_secs(15);
/// How long an upload may take: 100 MB over a slow Wi-Fi link.
const UPLOAD: Duration = Duration::from_secs(600);
/// The most of a host's error text a message quotes.
const QUOTE: usize = 200;
/// The most of an answer read (bytes): a status or a file list is
/// kilobytes; an answer past this is not the host's API, and reading it
/// whole could exhaust the server's memory.
pub const MAX_ANSWER: usize = 4 << 20;
/// The most of a refusal's text read (bytes): only [`QUOTE`] characters
/// of it are ever shown.
const MAX_REFUSAL: usize = 64 << 10;

/// A print host: its kind, address and secret.
#[derive(Clone)]
pub struct Link {
    kind: Kind,
    base: reqwest::Url,
    secret: Option<String>,
    http: reqwest::Client,
    /// The certificate accepted for an `https://` host, if one was.
    pin: Option<String>,
    /// The fingerprint the last TLS handshake was shown.
    seen: Option<std::sync::Arc<std::sync::Mutex<Option<String>>>>,
}

impl fmt::Debug for Link {
    // The secret stays out of logs and panics.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Link")
            .field("kind", &self.kind)
            .field("base", &self.base.as_str())
            .field("secret", &self.secret.as_ref().map(|_| "…"))
            .finish()
    }
}

/// The address as the keys file and messages spell it: no trailing slash.
pub fn normalize_url(url: &str) -> String {
    url.trim().trim_end_matches('/').to_string()
}

/// Checks a print host address: `http://` or `https://` with a host name
/// or IP address and optionally a port and path, no user name or password
/// in it.
pub fn check_url(url: &str) -> Result<reqwest::Url, LinkError> {
    let bad = |why: &str| LinkError::Address {
        url: url.to_string(),
        why: why.to_string(),
    };
    let u = reqwest::Url::parse(&normalize_url(url)).map_err(|e| {
        bad(&format!(
            "not an address ({e}); write it as http://octopi.local"
        ))
    })?;
    match u.scheme() {
        "http" | "https" => {}
        s => {
            return Err(bad(&format!(
                "`{s}:` is no web address; write it as http://octopi.local"
            )))
        }
    }
    if u.host_str().is_none_or(str::is_empty) {
        return Err(bad("no host name"));
    }
    if !u.username().is_empty() || u.password().is_some() {
        return Err(bad(
            "a user name or password in the address would be saved with the printer; give the key or password separately",
        ));
    }
    if u.query().is_some() || u.fragment().is_some() {
        return Err(bad("no `?` or `#` part, only the host, port and path"));
    }
    Ok(u)
}

impl Link {
    /// A link to the host at `url` with its API key or password, if it
    /// needs one; an `https://` host's certificate must be one this
    /// computer trusts.
    pub fn new(kind: Kind, url: &str, secret: Option<String>) -> Result<Link, LinkError> {
        Link::with_certificate(kind, url, secret, None)
    }

    /// A link as [`Link::new`], accepting for an `https://` host the
    /// certificate whose SHA-256 fingerprint is `cert_sha256` (a printer's
    /// own self-signed one) and no other.
    pub fn with_certificate(
        kind: Kind,
        url: &str,
        secret: Option<String>,
        cert_sha256: Option<&str>,
    ) -> Result<Link, LinkError> {
        let mut base = check_url(url)?;
        if !base.path().ends_with('/') {
            base.set_path(&format!("{}/", base.path()));
        }
        let bad = |why: String| LinkError::Address {
            url: url.to_string(),
            why,
        };
        let pin = cert_sha256
            .filter(|s| !s.trim().is_empty())
            .map(tls::parse_fingerprint)
            .transpose()
            .map_err(bad)?;
        tls::install_provider();
        let mut builder = reqwest::Client::builder()
            .connect_timeout(CONNECT)
            // Printers sit on the local network: no system proxy.
            .no_proxy()
            // A redirect would carry the key (a header, or a Duet's
            // password in the query) to wherever it points: follow none.
            .redirect(reqwest::redirect::Policy::none());
        let mut seen = None;
        if base.scheme() == "https" {
            let t = tls::host_tls(pin.clone()).map_err(bad)?;
            seen = Some(t.seen);
            builder = builder.tls_backend_preconfigured(t.config);
        }
        let http = builder.build().map_err(|e| bad(e.to_string()))?;
        Ok(Link {
            kind,
            base,
            secret: secret.filter(|s| !s.is_empty()),
            http,
            pin,
            seen,
        })
    }

    /// The host's kind.
    pub fn kind(&self) -> Kind {
        self.kind
    }

    /// The host's address, without a trailing slash.
    pub fn url(&self) -> String {
        normalize_url(self.base.as_str())
    }

    /// Uploads `gcode` as `name` (a file name, `.gcode` added if missing)
    /// and returns the name the host stored it under.
    pub async fn upload(&self, name: &str, gcode: Vec<u8>) -> Result<String, LinkError> {
        let name = file_name(name);
        match self.kind {
            Kind::OctoPrint => octoprint::upload(self, &name, gcode).await,
            Kind::Moonraker => moonraker::upload(self, &name, gcode).await,
            Kind::RepRap => reprap::upload(self, &name, gcode).await,
        }
    }

    /// Starts printing a file the host holds (the name [`Link::upload`]
    /// returned). Refused if the printer is busy or not connected.
    pub async fn start(&self, file: &str) -> Result<(), LinkError> {
        match self.kind {
            Kind::OctoPrint => octoprint::start(self, file).await,
            Kind::Moonraker => moonraker::start(self, file).await,
            Kind::RepRap => reprap::start(self, file).await,
        }
    }

    /// Pauses, resumes or cancels the print under way (docs/PRINTING.md,
    /// "Pause, resume, cancel"). Refused with the host's words where
    /// there is none to act on.
    pub async fn job(&self, action: JobAction) -> Result<(), LinkError> {
        match self.kind {
            Kind::OctoPrint => octoprint::job(self, action).await,
            Kind::Moonraker => moonraker::job(self, action).await,
            Kind::RepRap => reprap::job(self, action).await,
        }
    }

    /// What the printer is doing.
    pub async fn status(&self) -> Result<Status, LinkError> {
        match self.kind {
            Kind::OctoPrint => octoprint::status(self).await,
            Kind::Moonraker => moonraker::status(self).await,
            Kind::RepRap => reprap::status(self).await,
        }
    }

    /// The G-code files the host holds.
    pub async fn files(&self) -> Result<Vec<String>, LinkError> {
        match self.kind {
            Kind::OctoPrint => octoprint::files(self).await,
            Kind::Moonraker => moonraker::files(self).await,
            Kind::RepRap => reprap::files(self).await,
        }
    }

    /// The address of `path` under the host's base.
    fn at(&self, path: &str) -> reqwest::Url {
        // The base ends in `/` and `path` is relative: join cannot fail.
        self.base.join(path).unwrap_or_else(|_| self.base.clone())
    }

    /// Sends a request; a failure to connect is [`LinkError::Unreachable`],
    /// and a redirect is [`LinkError::Redirect`] (never followed).
    async fn send(
        &self,
        req: reqwest::RequestBuilder,
        timeout: Duration,
    ) -> Result<reqwest::Response, LinkError> {
        // The timeout runs until the answer's body is read, so a host that
        // trickles an endless answer is cut off too.
        let resp = req.timeout(timeout).send().await.map_err(|e| {
            if let Some(c) = self.certificate_error(&e) {
                return c;
            }
            let why = if e.is_timeout() {
                format!("no answer within {} s", timeout.as_secs())
            } else if e.is_connect() {
                "the connection was refused or timed out".to_string()
            } else {
                plain(&e)
            };
            LinkError::Unreachable {
                host: self.kind.title(),
                url: self.url(),
                why,
            }
        })?;
        if resp.status().is_redirection() {
            let to = resp
                .headers()
                .get(reqwest::header::LOCATION)
                .and_then(|l| l.to_str().ok())
                .map(|l| quote(l.split(['?', '#']).next().unwrap_or("")))
                .filter(|l| !l.is_empty())
                .unwrap_or_else(|| "an address it did not give".to_string());
            return Err(LinkError::Redirect {
                host: self.kind.title(),
                url: self.url(),
                status: resp.status().as_u16(),
                to,
            });
        }
        Ok(resp)
    }

    /// A failed request as a certificate refusal, when the handshake was
    /// shown a certificate and refused it.
    fn certificate_error(&self, e: &reqwest::Error) -> Option<LinkError> {
        let seen = self.seen.as_ref()?.lock().ok()?.clone()?;
        // A refused certificate fails the connection before any answer.
        if !e.is_connect() && !e.is_request() {
            return None;
        }
        let refused = match &self.pin {
            Some(pin) if *pin == seen => return None,
            Some(pin) => format!("other than the one accepted for it ({pin}): it may have been renewed, or another machine answers in its place"),
            None => {
                if !format!("{e:?}").to_lowercase().contains("certificate") {
                    return None;
                }
                "this computer does not trust (a self-signed one, as a printer's usually is)".to_string()
            }
        };
        Some(LinkError::Certificate {
            host: self.kind.title(),
            url: self.url(),
            why: refused,
            sha256: seen,
        })
    }

    /// At most `cap` bytes of an answer's body, or `None` (with what was
    /// read) when it runs past them: no answer is read into memory whole.
    async fn capped(
        &self,
        mut resp: reqwest::Response,
        cap: usize,
    ) -> Result<(Vec<u8>, bool), LinkError> {
        if resp.content_length().is_some_and(|n| n > cap as u64) {
            return Ok((Vec::new(), false));
        }
        let mut body = Vec::new();
        loop {
            match resp.chunk().await {
                Ok(Some(c)) if body.len() + c.len() > cap => {
                    let room = cap - body.len();
                    body.extend_from_slice(&c[..room]);
                    return Ok((body, false));
                }
                Ok(Some(c)) => body.extend_from_slice(&c),
                Ok(None) => return Ok((body, true)),
                Err(e) if e.is_timeout() => {
                    return Err(LinkError::Unreachable {
                        host: self.kind.title(),
                        url: self.url(),
                        why: "the answer did not finish in time".to_string(),
                    })
                }
                Err(e) => return Err(self.bad(plain(&e))),
            }
        }
    }

    /// A refusal's text, read to at most [`MAX_REFUSAL`] bytes (only its
    /// start is ever quoted).
    async fn text(&self, resp: reqwest::Response) -> String {
        match self.capped(resp, MAX_REFUSAL).await {
            Ok((b, _)) => String::from_utf8_lossy(&b).into_owned(),
            Err(_) => String::new(),
        }
    }

    /// A JSON answer of at most [`MAX_ANSWER`] bytes, or
    /// [`LinkError::BadAnswer`].
    async fn json(&self, resp: reqwest::Response) -> Result<serde_json::Value, LinkError> {
        let (body, whole) = self.capped(resp, MAX_ANSWER).await?;
        if !whole {
            return Err(self.bad(format!("an answer larger than {} MiB", MAX_ANSWER >> 20)));
        }
        let text = String::from_utf8_lossy(&body);
        serde_json::from_str(&text).map_err(|_| self.bad(format!("not JSON: {}", quote(&text))))
    }

    fn bad(&self, why: String) -> LinkError {
        LinkError::BadAnswer {
            host: self.kind.title(),
            url: self.url(),
            why,
        }
    }

    fn refused(&self, status: u16, message: &str) -> LinkError {
        LinkError::Refused {
            host: self.kind.title(),
            status,
            message: quote(message),
        }
    }
}

/// Whether a printer in state `s` may start a new print: not while it
/// prints (or is paused in a print), not while it is not connected.
fn ready_to_start(host: &'static str, s: Status) -> Result<(), LinkError> {
    if s.printing {
        return Err(LinkError::Busy {
            file: s.file.unwrap_or_default(),
        });
    }
    if !s.connected {
        return Err(LinkError::NotConnected {
            host,
            state: s.state,
        });
    }
    Ok(())
}

/// A file name the hosts store as G-code: no folders, `.gcode` at the end.
fn file_name(name: &str) -> String {
    let base = name.rsplit(['/', '\\']).next().unwrap_or(name);
    let clean: String = base
        .chars()
        .map(|c| if c.is_control() || c == '"' { '_' } else { c })
        .collect();
    let clean = if clean.trim().is_empty() {
        "sweepclay".to_string()
    } else {
        clean
    };
    let lower = clean.to_ascii_lowercase();
    if lower.ends_with(".gcode") || lower.ends_with(".g") || lower.ends_with(".gco") {
        clean
    } else {
        format!("{clean}.gcode")
    }
}

/// An error's words and its causes', without the URL (which may carry a
/// password in a query).
fn plain(e: &reqwest::Error) -> String {
    let mut s = match e.url() {
        Some(u) => e.to_string().replace(&format!(" ({u})"), ""),
        None => e.to_string(),
    };
    let mut src = std::error::Error::source(e);
    while let Some(c) = src {
        s.push_str(": ");
        s.push_str(&c.to_string());
        src = c.source();
    }
    s
}

/// At most [`QUOTE`] characters of a host's text, on one line.
fn quote(text: &str) -> String {
    let one: String = text.split_whitespace().collect::<Vec<_>>().join(" ");
    match one.char_indices().nth(QUOTE) {
        Some((i, _)) => format!("{}…", &one[..i]),
        None => one,
    }
}

/// Whether a host's error text says its storage is full.
fn says_full(text: &str) -> bool {
    let t = text.to_ascii_lowercase();
    t.contains("no space")
        || t.contains("disk full")
        || t.contains("not enough space")
        || t.contains("insufficient storage")
        || t.contains("enospc")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_are_http_or_https_without_credentials() {
        assert!(check_url("http://octopi.local").is_ok());
        assert!(check_url("http://192.168.1.20:7125/").is_ok());
        assert!(check_url("https://octopi.local").is_ok());
        for (url, says) in [
            ("https://pi:raspberry@octopi.local", "user name or password"),
            ("octopi.local", "not an address"),
            ("ftp://octopi.local", "no web address"),
            ("http://pi:raspberry@octopi.local", "user name or password"),
            ("http://octopi.local/?apikey=1", "no `?`"),
        ] {
            let e = check_url(url).unwrap_err().to_string();
            assert!(e.contains(says), "{url}: {e}");
        }
    }

    #[test]
    fn file_names_lose_folders_and_gain_gcode() {
        assert_eq!(file_name("/tmp/pot.gcode"), "pot.gcode");
        assert_eq!(file_name("C:\\pots\\vase"), "vase.gcode");
        assert_eq!(file_name("a\"b.GCODE"), "a_b.GCODE");
        assert_eq!(file_name(""), "sweepclay.gcode");
    }

    #[test]
    fn a_links_debug_form_hides_its_secret() {
        let l = Link::new(
            Kind::OctoPrint,
            "http://octopi.local",
            Some("SECRET".into()),
        )
        .unwrap();
        let s = format!("{l:?}");
        assert!(!s.contains("SECRET") && s.contains("octopi.local"), "{s}");
    }

    #[test]
    fn host_quotes_are_short_and_one_line() {
        let long = "x ".repeat(500);
        let q = quote(&long);
        assert!(q.chars().count() <= QUOTE + 1 && !q.contains('\n'));
        assert!(says_full("OSError: [Errno 28] No space left on device"));
        assert!(!says_full("File not found"));
    }
}
