//! `sweepclay serve`: the modeler's server on this machine or the LAN
//! (docs/MODELER.md), a thin shell over `sweepclay-web`.

use super::*;

#[derive(Args, Debug)]
pub(crate) struct ServeArgs {
    /// Address to listen on (use 0.0.0.0 to let other machines in).
    #[arg(long, default_value = "127.0.0.1")]
    pub(crate) host: String,
    /// Port (0 picks a free one).
    #[arg(long, default_value_t = 8080)]
    pub(crate) port: u16,
    /// Refuse designs with more surface samples than this (estimated).
    #[arg(long, default_value_t = DEFAULT_MAX_SAMPLES)]
    pub(crate) max_samples: u64,
    /// Longest a request may wait for a worker and run (seconds); its
    /// answer must begin within a minute longer.
    #[arg(long, default_value_t = 60)]
    pub(crate) timeout: u64,
    /// Most connections open at once (more wait to be accepted).
    #[arg(long, default_value_t = 256)]
    pub(crate) max_connections: usize,
    /// Longest a client may take to start a request, to send its headers,
    /// or to fall silent while sending its body (seconds); a body must
    /// also arrive at 64 KiB/s or faster on the whole.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..=3600))]
    pub(crate) read_timeout: u64,
    /// Another name the server answers to in Host, besides loopback, the
    /// address given and (with 0.0.0.0) the machine's own names and any IP
    /// address (repeatable): what keeps other sites' pages out.
    #[arg(long = "allow-host", value_name = "NAME")]
    pub(crate) allow_hosts: Vec<String>,
    /// A secret the page must carry to use the API; on any address but
    /// loopback (0.0.0.0, or one LAN address) one is made up and printed
    /// in the link unless given.
    #[arg(long)]
    pub(crate) token: Option<String>,
}

/// The machine's own names: its host name and that name in `.local`
/// (mDNS), as the studio's other machines reach it.
pub(crate) fn own_names() -> Vec<String> {
    let name = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .map(|n| n.trim().to_string())
        .unwrap_or_default();
    if name.is_empty() || name.len() > 253 {
        return Vec::new();
    }
    let local = format!("{name}.local");
    vec![name, local]
}

/// 128 random bits as hex, from the standard library's per-process
/// random hash keys (no extra crate for one secret).
pub(crate) fn random_token() -> String {
    use std::hash::{BuildHasher, Hasher};
    (0..2)
        .map(|i| {
            let mut h = std::collections::hash_map::RandomState::new().build_hasher();
            h.write_u64(i);
            h.write_u128(
                std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.as_nanos()),
            );
            format!("{:016x}", h.finish())
        })
        .collect()
}

pub(crate) fn serve(a: ServeArgs) -> Result<i32> {
    let rt = tokio::runtime::Runtime::new().context("starting the async runtime")?;
    rt.block_on(async {
        eprintln!(
            "sweepclay {VERSION}: starting the modeler on {}:{} ...",
            a.host, a.port
        );
        let listener = tokio::net::TcpListener::bind((a.host.as_str(), a.port))
            .await
            .with_context(|| format!("listening on {}:{}", a.host, a.port))?;
        let addr = listener.local_addr()?;
        let host = if addr.ip().is_unspecified() {
            "127.0.0.1".to_string()
        } else {
            addr.ip().to_string()
        };
        let lan = addr.ip().is_unspecified();
        let token = a
            .token
            .clone()
            .or_else(|| token_required(addr.ip()).then(random_token));
        if token.as_ref().is_some_and(|t| {
            t.is_empty()
                || !t
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        }) {
            bail!("--token: letters, digits, - and _ only, not empty");
        }
        let link = |h: &str| match &token {
            Some(t) => format!("http://{h}:{}/?token={t}", addr.port()),
            None => format!("http://{h}:{}/", addr.port()),
        };
        say!("sweepclay modeler: {}  (Ctrl+C to stop)", link(&host));
        if lan {
            for name in own_names().iter().take(1) {
                say!("  from the studio's other machines: {}", link(name));
            }
        }
        let defaults = sweepclay_web::api::Limits::default();
        let mut limits = sweepclay_web::api::Limits {
            max_samples: a.max_samples as f64,
            request_timeout: std::time::Duration::from_secs(a.timeout),
            // A client has --read-timeout to send; an answer may take a
            // minute more than the longest request.
            connections: sweepclay_web::conn::Connections {
                max: a.max_connections,
                read: std::time::Duration::from_secs(a.read_timeout),
                answer: std::time::Duration::from_secs(a.timeout + 60),
            },
            ..defaults
        };
        // Loopback's names, the address given, --allow-host; bound to every
        // interface on purpose (LAN mode), also the machine's names and any
        // IP address — never any name, which let DNS rebinding in.
        let mut names = a.allow_hosts.clone();
        if lan {
            names.extend(own_names());
        } else {
            names.push(a.host.clone());
        }
        for n in names {
            if !limits.hosts.iter().any(|h| h.eq_ignore_ascii_case(&n)) {
                limits.hosts.push(n);
            }
        }
        limits.lan = lan;
        limits.token = token;
        sweepclay_web::run(listener, limits).await?;
        Ok(0)
    })
}

/// Whether a server bound to `ip` must want a token: any address other
/// machines can reach — every interface, or one LAN address such as
/// `192.168.1.20` (it let the whole network in without one) — not
/// loopback.
pub(crate) fn token_required(ip: std::net::IpAddr) -> bool {
    !ip.is_loopback()
}
