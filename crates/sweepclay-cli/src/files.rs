//! Files in and out: inputs read under a cap and only when regular;
//! outputs written beside their place and renamed over it, never over an
//! input or anything that is not a regular file.

use super::*;

/// Reads a file of at most `cap` bytes, refusing a larger one before
/// reading it whole.
pub(crate) fn read_capped(path: &Path, cap: usize) -> std::result::Result<Vec<u8>, String> {
    use std::io::Read;
    // A FIFO or a device would block or never end: only regular files.
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => {
            return Err(format!(
                "{}: not a regular file (a directory, device or FIFO)",
                path.display()
            ))
        }
        _ => {}
    }
    let f = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut bytes = Vec::new();
    f.take(cap as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if bytes.len() > cap {
        return Err(format!("{} is over the cap of {cap} bytes", path.display()));
    }
    Ok(bytes)
}

/// The file an output path names: itself if missing, its target if it is
/// a symbolic link to a regular file; anything that is not a regular file
/// (a directory, a device, a FIFO) is refused, never replaced.
pub(crate) fn output_target(path: &Path) -> Result<PathBuf> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {
            std::fs::canonicalize(path).with_context(|| format!("resolving {}", path.display()))
        }
        Ok(_) => bail!(
            "{}: not a regular file (a directory, device or FIFO); refusing to replace it",
            path.display()
        ),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if std::fs::symlink_metadata(path).is_ok() {
                bail!(
                    "{}: a symbolic link to nothing; refusing to follow it",
                    path.display()
                );
            }
            Ok(path.to_path_buf())
        }
        Err(e) => Err(e).with_context(|| format!("checking {}", path.display())),
    }
}

/// Refuses an output (`flag` `target`) that is one of the command's
/// input files: `calibrate --printer P.json -o P.json` wrote the print
/// over the profile it read. Paths that do not exist are no input.
pub(crate) fn not_an_input(flag: &str, target: &Path, inputs: &[&Path]) -> Result<()> {
    let Ok(out) = std::fs::canonicalize(target) else {
        return Ok(());
    };
    for input in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i == out) {
            bail!(
                "{flag} {}: that is an input ({}); refusing to write over it",
                target.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// The prefix of our temporary files: `.sweepclay-tmp-NAME.` and random
/// letters, beside the file NAME they will replace.
pub(crate) const TMP_PREFIX: &str = ".sweepclay-tmp-";

/// A temporary file older than this (seconds) beside the output is a
/// run's leftover (a kill -9 runs no clean-up) and is removed.
pub(crate) const STALE_TMP_S: u64 = 600;

/// An empty temporary file in the directory of `path`, to be renamed over
/// it by [`persist`] (deleted if dropped or if the command is interrupted).
/// It is named for `path`, so the next run finds a killed run's leftover
/// and removes it (once it is [`STALE_TMP_S`] old, so a run still going
/// keeps its own).
pub(crate) fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!("{TMP_PREFIX}{name}.");
    remove_stale(dir, &prefix);
    let tmp = tempfile::Builder::new()
        .prefix(&prefix)
        .tempfile_in(dir)
        .with_context(|| format!("creating a temporary file in {}", dir.display()))?;
    if let Ok(mut live) = LIVE.lock() {
        live.push(tmp.path().to_path_buf());
    }
    Ok(tmp)
}

/// Removes our leftover temporary files for one output (`prefix`) in
/// `dir` that are older than [`STALE_TMP_S`]; what cannot be removed is
/// left.
pub(crate) fn remove_stale(dir: &Path, prefix: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let old = e
            .metadata()
            .ok()
            .filter(|m| m.is_file())
            .and_then(|m| m.modified().ok())
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age.as_secs() >= STALE_TMP_S);
        if old && e.file_name().to_string_lossy().starts_with(prefix) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Makes a finished temporary file `path`: an ordinary file with the mode
/// of the file it replaces (0644 for a new one; temporary files are
/// private, 0600), synced, then renamed, so a crash never leaves a
/// half-written file.
pub(crate) fn persist(tmp: tempfile::NamedTempFile, path: &Path) -> Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path).map_or(0o644, |m| m.permissions().mode() & 0o7777);
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(mode))?;
    }
    tmp.as_file().sync_all()?;
    let name = tmp.path().to_path_buf();
    let done = tmp
        .persist(path)
        .with_context(|| format!("writing {}", path.display()));
    if let Ok(mut live) = LIVE.lock() {
        live.retain(|p| *p != name);
    }
    done.map(|_| ())
}

/// Writes through a temporary file in the same directory and renames it.
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let path = output_target(path)?;
    let mut tmp = temp_beside(&path)?;
    tmp.write_all(bytes)?;
    persist(tmp, &path)
}
