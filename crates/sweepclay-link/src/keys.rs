//! Where print hosts' API keys and passwords are kept: one JSON file in the
//! user's configuration directory, `{"http://octopi.local": "KEY", …}`,
//! readable by its owner only. Never in a printer profile, a design or a
//! log (docs/PRINTING.md, "Keys").
//!
//! The directory is `$SWEEPCLAY_CONFIG_DIR`, else
//! `$XDG_CONFIG_HOME/sweepclay`, else `~/.config/sweepclay`. For one
//! command, `$SWEEPCLAY_HOST_KEY` overrides the file.

use crate::normalize_url;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The keys file's name in the configuration directory.
pub const FILE: &str = "host-keys.json";

/// The largest keys file read (bytes): a few keys, not a database.
const MAX_BYTES: u64 = 1 << 20;

/// The configuration directory, from the environment.
pub fn config_dir() -> Option<PathBuf> {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    env("SWEEPCLAY_CONFIG_DIR")
        .or_else(|| env("XDG_CONFIG_HOME").map(|d| d.join("sweepclay")))
        .or_else(|| env("HOME").map(|h| h.join(".config").join("sweepclay")))
}

/// The keys file in a configuration directory.
pub fn path_in(dir: &Path) -> PathBuf {
    dir.join(FILE)
}

/// The keys file in the configuration directory the environment names
/// ([`config_dir`]), if it names one.
pub fn default_path() -> Option<PathBuf> {
    config_dir().map(|d| path_in(&d))
}

/// Reads the keys file; a missing file is no keys.
pub fn read(path: &Path) -> Result<BTreeMap<String, String>, String> {
    let bytes = match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(BTreeMap::new()),
        Err(e) => return Err(format!("{}: {e}", path.display())),
        Ok(m) if m.len() > MAX_BYTES => {
            return Err(format!(
                "{}: larger than {MAX_BYTES} bytes; is it the keys file?",
                path.display()
            ))
        }
        Ok(_) => std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?,
    };
    serde_json::from_slice(&bytes).map_err(|e| {
        format!(
            "{}: not a keys file ({e}); it holds {{\"http://host\": \"key\"}}",
            path.display()
        )
    })
}

/// The key for `url` in the keys file, or `$SWEEPCLAY_HOST_KEY`.
pub fn lookup(path: Option<&Path>, url: &str) -> Result<Option<String>, String> {
    if let Some(k) = std::env::var_os("SWEEPCLAY_HOST_KEY") {
        return Ok(Some(k.to_string_lossy().into_owned()));
    }
    match path {
        Some(p) => Ok(read(p)?.remove(&normalize_url(url))),
        None => Ok(None),
    }
}

/// Saves `key` for `url` (an empty key forgets it), written whole to a
/// temporary file readable by its owner only, then renamed over the old.
pub fn save(path: &Path, url: &str, key: &str) -> Result<(), String> {
    let mut keys = read(path)?;
    let url = normalize_url(url);
    if key.is_empty() {
        keys.remove(&url);
    } else {
        keys.insert(url, key.to_string());
    }
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    // tempfile creates its files 0600 on Unix.
    let mut tmp =
        tempfile::NamedTempFile::new_in(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let text = serde_json::to_string_pretty(&keys).map_err(|e| e.to_string())?;
    tmp.write_all(text.as_bytes())
        .and_then(|_| tmp.as_file().sync_all())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    tmp.persist(path)
        .map_err(|e| format!("{}: {}", path.display(), e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_saved_by_address_and_only_for_the_owner() {
        let dir = tempfile::tempdir().unwrap();
        let path = path_in(dir.path());
        assert!(read(&path).unwrap().is_empty());
        save(&path, "http://octopi.local/", "K1").unwrap();
        save(&path, "http://duet.local", "K2").unwrap();
        let keys = read(&path).unwrap();
        assert_eq!(
            keys.get("http://octopi.local").map(String::as_str),
            Some("K1")
        );
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&path).unwrap().permissions().mode();
            assert_eq!(mode & 0o077, 0, "{mode:o}");
        }
        save(&path, "http://octopi.local", "").unwrap();
        assert_eq!(read(&path).unwrap().len(), 1);
        std::fs::write(&path, "[1,2]").unwrap();
        assert!(read(&path).unwrap_err().contains("not a keys file"));
    }
}
