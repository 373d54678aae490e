//! Hot reload: whether the scene file changed since it was last loaded, by its
//! modification time and size (one `stat` per check).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

/// How often the file is looked at, at most.
const CHECK_INTERVAL: Duration = Duration::from_millis(250);

/// What a `stat` of the file says; `None` while it cannot be read (an editor that
/// replaces the file may leave a moment without one).
type Stamp = Option<(SystemTime, u64)>;

fn stamp(path: &Path) -> Stamp {
    let metadata = std::fs::metadata(path).ok()?;
    Some((metadata.modified().ok()?, metadata.len()))
}

/// Watches one file for changes.
#[derive(Debug)]
pub struct SceneWatcher {
    path: PathBuf,
    seen: Stamp,
    last_check: Option<Instant>,
}

impl SceneWatcher {
    /// Starts watching `path` as it is now.
    pub fn new(path: &Path) -> Self {
        Self {
            path: path.to_path_buf(),
            seen: stamp(path),
            last_check: None,
        }
    }

    /// Whether the file changed (modification time or size) since the last time this
    /// returned `true` or the watcher was made, looking at it at most every
    /// [`CHECK_INTERVAL`]. A file that is missing for the moment is no change.
    pub fn changed(&mut self) -> bool {
        let now = Instant::now();
        if self
            .last_check
            .is_some_and(|last| now.duration_since(last) < CHECK_INTERVAL)
        {
            return false;
        }
        self.last_check = Some(now);
        self.changed_now()
    }

    /// [`SceneWatcher::changed`] without the rate limit.
    pub fn changed_now(&mut self) -> bool {
        let current = stamp(&self.path);
        if current.is_none() || current == self.seen {
            return false;
        }
        self.seen = current;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs::File;
    use std::io::Write;

    #[test]
    fn reports_each_change_once() {
        let dir = tempfile::tempdir().expect("temporary directory");
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, "a").expect("write");
        let file = File::options().write(true).open(&path).expect("open");
        let start = SystemTime::UNIX_EPOCH + Duration::from_secs(1_000_000);
        file.set_modified(start).expect("set mtime");
        let mut watcher = SceneWatcher::new(&path);
        assert!(!watcher.changed_now(), "nothing changed yet");

        file.set_modified(start + Duration::from_secs(1))
            .expect("set mtime");
        assert!(watcher.changed_now(), "a new modification time");
        assert!(!watcher.changed_now(), "the same change twice");

        // Same modification time, other size (a coarse-mtime file system).
        let mut writer = File::options().append(true).open(&path).expect("open");
        writer.write_all(b"bc").expect("append");
        file.set_modified(start + Duration::from_secs(1))
            .expect("set mtime");
        assert!(watcher.changed_now(), "a new size");

        // A file missing for a moment is no change; its return is one.
        std::fs::remove_file(&path).expect("remove");
        assert!(!watcher.changed_now(), "missing");
        std::fs::write(&path, "a").expect("write again");
        assert!(watcher.changed_now(), "back again");
    }
}
