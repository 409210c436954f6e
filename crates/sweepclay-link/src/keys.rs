//! Where print hosts' API keys and passwords are kept: one JSON file in the
//! user's configuration directory, `{"http://octopi.local": "KEY", …}`,
//! readable by its owner only. Never in a printer profile, a design or a
//! log (docs/PRINTING.md, "Keys").
//!
//! The directory is `$SWEEPCLAY_CONFIG_DIR`, else
//! `$XDG_CONFIG_HOME/sweepclay`, else `~/.config/sweepclay`. For one CLI
//! command, `$SWEEPCLAY_HOST_KEY` overrides the file; the server never
//! reads it. The file is also the list of hosts the user saved: a host
//! saved without a key maps to `""`, and the server talks to no other.

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

/// The key saved for `url` in the keys file, if any. A host saved
/// without a key is `None` too: [`saved`] tells them apart.
pub fn lookup(path: Option<&Path>, url: &str) -> Result<Option<String>, String> {
    Ok(saved(path, url)?.flatten())
}

/// Whether `url` is a host saved in the keys file (`Some`), and its key
/// if it has one. The server talks only to saved hosts
/// (docs/PRINTING.md, "What the link sends where").
pub fn saved(path: Option<&Path>, url: &str) -> Result<Option<Option<String>>, String> {
    match path {
        Some(p) => Ok(read(p)?
            .remove(&normalize_url(url))
            .map(|k| Some(k).filter(|k| !k.is_empty()))),
        None => Ok(None),
    }
}

/// `$SWEEPCLAY_HOST_KEY`: a key for the one host a command names. Only the
/// CLI reads it; the server never does, since a request could name any
/// host (docs/PRINTING.md, "Keys").
pub fn from_env() -> Option<String> {
    std::env::var_os(ENV_KEY)
        .map(|k| k.to_string_lossy().trim().to_string())
        .filter(|k| !k.is_empty())
}

/// The environment variable [`from_env`] reads.
pub const ENV_KEY: &str = "SWEEPCLAY_HOST_KEY";

/// What [`update`] does to one host's entry.
#[derive(Clone, Debug, PartialEq)]
pub enum Change<'a> {
    /// Save the host with this key (an empty key: the host takes none).
    Key(&'a str),
    /// Save the host, keeping the key it has (none if it is new).
    Keep,
    /// Forget the host and its key.
    Forget,
}

/// Saves `key` for `url` (an empty key forgets it), as `sweepclay send
/// --save-key` does.
pub fn save(path: &Path, url: &str, key: &str) -> Result<(), String> {
    if key.is_empty() {
        update(path, url, Change::Forget)
    } else {
        update(path, url, Change::Key(key))
    }
}

/// Serialises read-modify-writes of the keys file within this process;
/// the file lock below does it across processes.
static WRITING: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Changes one host's entry: read, change and write whole under a lock, so
/// saves at once never lose one another; written to a temporary file
/// readable by its owner only, then renamed over the old.
pub fn update(path: &Path, url: &str, change: Change<'_>) -> Result<(), String> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let _in_process = WRITING.lock().unwrap_or_else(|p| p.into_inner());
    let lock_path = path.with_extension("lock");
    let lock = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .map_err(|e| format!("{}: {e}", lock_path.display()))?;
    lock.lock()
        .map_err(|e| format!("{}: {e}", lock_path.display()))?;
    let mut keys = read(path)?;
    let url = normalize_url(url);
    match change {
        Change::Key(k) => {
            keys.insert(url, k.to_string());
        }
        Change::Keep => {
            keys.entry(url).or_default();
        }
        Change::Forget => {
            keys.remove(&url);
        }
    }
    // tempfile creates its files 0600 on Unix.
    let mut tmp =
        tempfile::NamedTempFile::new_in(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let text = serde_json::to_string_pretty(&keys).map_err(|e| e.to_string())?;
    tmp.write_all(text.as_bytes())
        .and_then(|_| tmp.as_file().sync_all())
        .map_err(|e| format!("{}: {e}", path.display()))?;
    tmp.persist(path)
        .map_err(|e| format!("{}: {}", path.display(), e.error))?;
    // The lock is released when `lock` is dropped.
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
        update(&path, "http://moonraker.local", Change::Keep).unwrap();
        assert_eq!(
            saved(Some(&path), "http://moonraker.local/"),
            Ok(Some(None))
        );
        assert_eq!(saved(Some(&path), "http://other.local"), Ok(None));
        update(&path, "http://duet.local", Change::Keep).unwrap();
        assert_eq!(
            lookup(Some(&path), "http://duet.local"),
            Ok(Some("K2".into()))
        );
        std::fs::write(&path, "[1,2]").unwrap();
        assert!(read(&path).unwrap_err().contains("not a keys file"));
    }
}

#[cfg(test)]
mod concurrent {
    use super::*;

    #[test]
    fn saves_at_once_lose_none() {
        // Before the lock, 50 saves at once kept 3 (issue: reliability 4).
        let dir = tempfile::tempdir().unwrap();
        let path = path_in(dir.path());
        std::thread::scope(|s| {
            for i in 0..50 {
                let path = &path;
                s.spawn(move || save(path, &format!("http://printer{i}.local"), "K").unwrap());
            }
        });
        assert_eq!(read(&path).unwrap().len(), 50);
    }
}
