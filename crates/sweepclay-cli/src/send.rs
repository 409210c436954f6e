//! `sweepclay send`: check a G-code file, upload it to the printer's print
//! host, start it and follow it (docs/PRINTING.md). A thin shell over
//! `sweepclay-check` and `sweepclay-link`.

use crate::{base_check_config, load_printer, say};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Duration;
use sweepclay_check::check_reader;
use sweepclay_link::{keys, Kind, Link};

/// The largest file sent (bytes): a long clay print is tens of MB.
const MAX_SEND_BYTES: usize = 1 << 30;

/// How often the print's progress is asked for.
const POLL: Duration = Duration::from_secs(2);

#[derive(Args, Debug)]
pub struct SendArgs {
    /// The G-code file to send.
    file: PathBuf,
    /// Printer preset or printer JSON file whose `host` names the print
    /// host (and whose values the check uses) [default: the printer a
    /// sweepclay file's header names, for the check].
    #[arg(long)]
    printer: Option<String>,
    /// The print host's address, e.g. `http://octopi.local` (instead of the
    /// printer's `host`).
    #[arg(long, value_name = "URL")]
    host: Option<String>,
    /// An `https://` host's own certificate to accept, by its SHA-256
    /// fingerprint (as the refusal names it) [default: the printer's
    /// `host.cert_sha256`; none: this computer's trusted roots].
    #[arg(long, value_name = "SHA256")]
    cert_sha256: Option<String>,
    /// The print host's kind with --host: octoprint, moonraker or reprap.
    #[arg(long, value_name = "KIND")]
    kind: Option<String>,
    /// The file's name on the host [default: the file's own name].
    #[arg(long)]
    name: Option<String>,
    /// Start printing it once uploaded.
    #[arg(long)]
    start: bool,
    /// Start it and follow the print until it ends, showing its progress.
    #[arg(long)]
    watch: bool,
    /// Send a file that fails the check (with a warning).
    #[arg(long)]
    force: bool,
    /// Read the host's API key or password from standard input (one
    /// line) and save it for this host in the keys file, readable by you
    /// only (docs/PRINTING.md, "Keys").
    #[arg(long)]
    save_key: bool,
}

/// The host's kind, address and accepted certificate, from the flags or
/// the printer profile.
fn host_of(a: &SendArgs) -> Result<(Kind, String, Option<String>)> {
    if let Some(url) = &a.host {
        let kind = a.kind.as_deref().context(
            "--host: also say which host it is with --kind octoprint, --kind moonraker or --kind reprap",
        )?;
        let kind = Kind::from_name(kind)
            .with_context(|| format!("--kind: `{kind}` is none of octoprint, moonraker, reprap"))?;
        return Ok((kind, url.clone(), a.cert_sha256.clone()));
    }
    if a.kind.is_some() {
        bail!("--kind goes with --host URL");
    }
    let Some(spec) = &a.printer else {
        bail!("say where to send it: --printer PROFILE.json whose `host` names the print host, or --host URL --kind octoprint|moonraker|reprap (docs/PRINTING.md)");
    };
    let p = load_printer(spec)?;
    let h = p.host.with_context(|| {
        format!("--printer {spec}: the profile names no print host; add \"host\": {{\"kind\": \"octoprint\", \"url\": \"http://octopi.local\"}} to it, or pass --host URL --kind KIND (docs/PRINTING.md)")
    })?;
    let kind =
        Kind::from_name(h.kind.name()).context("a print host kind the link does not know")?;
    Ok((kind, h.url, a.cert_sha256.clone().or(h.cert_sha256)))
}

pub fn run(a: SendArgs) -> Result<i32> {
    let (kind, url, cert) = host_of(&a)?;
    sweepclay_link::check_url(&url).map_err(|e| anyhow::anyhow!("{e}"))?;
    let keys_file = keys::default_path();
    if a.save_key {
        let path = keys_file
            .as_ref()
            .context("--save-key: no configuration directory (set HOME or SWEEPCLAY_CONFIG_DIR)")?;
        let mut line = String::new();
        std::io::stdin()
            .read_line(&mut line)
            .context("--save-key: reading the key from standard input")?;
        keys::save(path, &url, line.trim()).map_err(|e| anyhow::anyhow!("--save-key: {e}"))?;
        eprintln!(
            "saved the key for {} in {}",
            sweepclay_link::normalize_url(&url),
            path.display()
        );
    }
    // The environment's key is for the one host this command names.
    let secret = match keys::from_env() {
        Some(k) => Some(k),
        None => keys::lookup(keys_file.as_deref(), &url).map_err(|e| anyhow::anyhow!("{e}"))?,
    };

    let bytes = crate::read_capped(&a.file, MAX_SEND_BYTES).map_err(|e| anyhow::anyhow!(e))?;
    // The check first: a file that fails it is not sent without --force.
    let cfg = base_check_config(&a.file, a.printer.as_deref())?;
    let report = check_reader(std::io::BufReader::new(bytes.as_slice()), &cfg)
        .with_context(|| format!("checking {}", a.file.display()))?;
    let verdict = report.render();
    let summary = verdict.lines().next().unwrap_or("").to_string();
    if !report.printable || report.cannot_judge.is_some() {
        if !a.force {
            eprintln!("{summary}");
            eprintln!("not sent: the file does not pass `sweepclay check` (see `sweepclay check {}`); fix it, or send it anyway with --force", a.file.display());
            return Ok(1);
        }
        eprintln!("WARNING: sending a file that does NOT pass the check (--force): {summary}");
    }

    let name = a.name.clone().unwrap_or_else(|| file_name(&a.file));
    let link = Link::with_certificate(kind, &url, secret, cert.as_deref())
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the network runtime")?;
    let size = bytes.len();
    rt.block_on(async {
        eprintln!(
            "uploading {name} ({}) to {kind} at {}…",
            human_size(size),
            link.url()
        );
        let stored = link.upload(&name, bytes).await?;
        say(format_args!(
            "sent       {stored} to {kind} at {}\n",
            link.url()
        ))?;
        if !(a.start || a.watch) {
            return Ok(0);
        }
        link.start(&stored).await?;
        say(format_args!("started    {stored}\n"))?;
        if a.watch {
            follow(&link).await?;
        }
        Ok::<i32, anyhow::Error>(0)
    })
    .map_err(|e| match e.downcast::<sweepclay_link::LinkError>() {
        Ok(le) => match &le {
            sweepclay_link::LinkError::Certificate { sha256, .. } => anyhow::anyhow!("{le}: send again with --cert-sha256 {sha256}, or put \"cert_sha256\": \"{sha256}\" in the printer's host"),
            _ => anyhow::anyhow!("{le}"),
        },
        Err(e) => e,
    })
}

/// Shows the print's progress until it ends: a line at every tenth, and
/// the final state.
async fn follow(link: &Link) -> Result<()> {
    let mut shown = -1i64;
    // A host may take a moment to report a just-started job as printing.
    let mut seen_printing = false;
    for polls in 0u64.. {
        let s = link.status().await?;
        if s.printing {
            seen_printing = true;
            let tenth = s.progress.map_or(0, |p| (p * 10.0).floor() as i64);
            if tenth > shown {
                shown = tenth;
                say(format_args!(
                    "printing   {} {:>3.0} %  ({})\n",
                    s.file.as_deref().unwrap_or(""),
                    s.progress.unwrap_or(0.0) * 100.0,
                    s.state
                ))?;
            }
        } else if seen_printing || polls > 5 {
            let done = s.progress.map_or(String::new(), |p| {
                format!(", {:.0} % of the file", p * 100.0)
            });
            say(format_args!("ended      {}{done}\n", s.state))?;
            return Ok(());
        }
        tokio::time::sleep(POLL).await;
    }
    Ok(())
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "sweepclay.gcode".into())
}

fn human_size(bytes: usize) -> String {
    if bytes >= 1 << 20 {
        format!("{:.1} MB", bytes as f64 / (1u64 << 20) as f64)
    } else {
        format!("{:.0} kB", (bytes as f64 / 1024.0).ceil())
    }
}
