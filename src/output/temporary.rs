//! The temporary file an output is written to before it takes the output's place,
//! and the registry that lets a signal handler cancel the writes in progress.
//!
//! On Linux the file is created without a name (`O_TMPFILE`): a process killed while
//! writing it (SIGKILL, which no handler sees: what Slurm and Kubernetes send after
//! their grace period) leaves nothing behind, as the kernel frees an unnamed file with
//! its last descriptor. Only once it is complete and synced is it given a name beside
//! the output (`linkat`) and renamed over the output at once. Where unnamed files are
//! not available (other systems, file systems without them such as NFS), the file is
//! named from the start; its name, `.gpu-render-HOST-PID-XXXXXX.tmp`, says which
//! process on which machine writes it, so that the next write into the same folder
//! removes the files of processes of this machine that no longer run.

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use super::OutputError;

/// The temporary files of the writes in progress, and whether they were cancelled.
struct Pending {
    paths: Vec<PathBuf>,
    cancelled: bool,
}

static PENDING: Mutex<Pending> = Mutex::new(Pending {
    paths: Vec::new(),
    cancelled: false,
});

fn pending() -> MutexGuard<'static, Pending> {
    PENDING
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Removes the temporary file of every write in progress and makes those writes, and
/// every later one, fail with [`OutputError::Cancelled`] instead of renaming anything
/// into place. Meant for a signal handler that then exits: afterwards no output of
/// this process is replaced, and none of its temporary files remains. A write whose
/// rename already started completes first (this waits for it). Returns how many
/// named temporary files were removed (unnamed ones vanish with the process).
pub fn cancel_pending_writes() -> usize {
    let mut pending = pending();
    pending.cancelled = true;
    pending
        .paths
        .drain(..)
        .filter(|path| std::fs::remove_file(path).is_ok())
        .count()
}

/// A file being written in place of `path`, in `path`'s folder.
pub(super) struct Temporary {
    file: File,
    /// Its name while it has one (always for a named temporary file).
    name: Option<PathBuf>,
    dir: PathBuf,
}

impl Temporary {
    /// Creates the temporary file for `path` in `dir` (unnamed where the system and
    /// file system allow it), after removing stale named ones of dead processes of
    /// this machine. Fails with [`OutputError::Cancelled`] after
    /// [`cancel_pending_writes`].
    pub(super) fn create(path: &Path, dir: &Path) -> Result<Self, OutputError> {
        let io_error = |error| OutputError::Io {
            path: path.to_path_buf(),
            action: format!("create a temporary file in {}", dir.display()),
            error,
        };
        remove_stale(dir);
        // Created and registered under the lock, so a cancellation sees it or prevents it.
        let mut pending = pending();
        if pending.cancelled {
            return Err(cancelled(path));
        }
        if let Some(file) = unnamed_file(dir) {
            return Ok(Self {
                file,
                name: None,
                dir: dir.to_path_buf(),
            });
        }
        let (file, name) = new_name(dir, |name| {
            std::fs::OpenOptions::new()
                .write(true)
                .read(true)
                .create_new(true)
                .open(name)
        })
        .map_err(io_error)?;
        pending.paths.push(name.clone());
        Ok(Self {
            file,
            name: Some(name),
            dir: dir.to_path_buf(),
        })
    }

    /// The file to write into.
    pub(super) fn file_mut(&mut self) -> &mut File {
        &mut self.file
    }

    /// The file, to sync it.
    pub(super) fn file(&self) -> &File {
        &self.file
    }

    /// Moves the finished (flushed and synced) file into `path`'s place, unless the
    /// writes were cancelled. The name is given and the rename done under the lock, so
    /// that a cancellation waits for them rather than racing them.
    pub(super) fn persist(mut self, path: &Path) -> Result<(), OutputError> {
        let mut pending = pending();
        if pending.cancelled {
            drop(pending);
            self.discard();
            return Err(cancelled(path));
        }
        let io_error = |error| OutputError::Io {
            path: path.to_path_buf(),
            action: "move the finished file into place".to_owned(),
            error,
        };
        let name = match self.name.take() {
            Some(name) => name,
            None => match link_unnamed(&self.file, &self.dir) {
                Ok(name) => name,
                Err(error) => return Err(io_error(error)),
            },
        };
        pending.paths.retain(|p| *p != name);
        std::fs::rename(&name, path).map_err(|error| {
            // Still under the lock: deleted before a cancellation could miss it.
            let _ = std::fs::remove_file(&name);
            io_error(error)
        })
    }

    /// Deletes the file (a named one is also forgotten), under the lock, so that no
    /// signal can arrive between the two and leave it behind.
    pub(super) fn discard(mut self) {
        if let Some(name) = self.name.take() {
            let mut pending = pending();
            pending.paths.retain(|p| *p != name);
            // Best effort: a file that cannot be deleted cannot be helped here.
            let _ = std::fs::remove_file(&name);
        }
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if let Some(name) = self.name.take() {
            let mut pending = pending();
            pending.paths.retain(|p| *p != name);
            let _ = std::fs::remove_file(&name);
        }
    }
}

fn cancelled(path: &Path) -> OutputError {
    OutputError::Cancelled {
        path: path.to_path_buf(),
    }
}

/// The start of this process's temporary file names: `.gpu-render-HOST-PID-`.
fn own_prefix() -> String {
    format!("{}{}-", host_prefix(), std::process::id())
}

/// `.gpu-render-HOST-`, with the host name reduced to letters, digits and dots.
fn host_prefix() -> String {
    let host: String = host_name()
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '.')
        .take(48)
        .collect();
    format!(".gpu-render-{host}-")
}

#[cfg(unix)]
fn host_name() -> String {
    rustix::system::uname()
        .nodename()
        .to_string_lossy()
        .into_owned()
}

#[cfg(not(unix))]
fn host_name() -> String {
    std::env::var("COMPUTERNAME").unwrap_or_default()
}

/// Runs `make` on new names `dir/.gpu-render-HOST-PID-XXXXXX.tmp` until one does not
/// exist yet; returns what it made and the name.
fn new_name<T>(
    dir: &Path,
    mut make: impl FnMut(&Path) -> io::Result<T>,
) -> io::Result<(T, PathBuf)> {
    let prefix = own_prefix();
    let mut error = None;
    for attempt in 0..64u32 {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let tag = (nanos ^ attempt.wrapping_mul(0x9e37_79b9)) & 0xff_ffff;
        let name = dir.join(format!("{prefix}{tag:06x}.tmp"));
        match make(&name) {
            Ok(made) => return Ok((made, name)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => error = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(error.unwrap_or_else(|| io::Error::other("no free temporary file name")))
}

/// An unnamed file in `dir`, or `None` where the system or file system has none.
#[cfg(any(target_os = "linux", target_os = "android"))]
fn unnamed_file(dir: &Path) -> Option<File> {
    use rustix::fs::{Mode, OFlags};
    // rw for everyone, narrowed by the umask, as an ordinary new file.
    let mode = Mode::from_raw_mode(0o666);
    rustix::fs::open(dir, OFlags::TMPFILE | OFlags::RDWR | OFlags::CLOEXEC, mode)
        .ok()
        .map(File::from)
}

#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn unnamed_file(_: &Path) -> Option<File> {
    None
}

/// Gives the unnamed `file` a new temporary name in `dir` (through its `/proc/self/fd`
/// entry, which needs no privilege); returns the name.
#[cfg(any(target_os = "linux", target_os = "android"))]
fn link_unnamed(file: &File, dir: &Path) -> io::Result<PathBuf> {
    use std::os::fd::AsRawFd;

    use rustix::fs::{AtFlags, CWD};
    let source = format!("/proc/self/fd/{}", file.as_raw_fd());
    let ((), name) = new_name(dir, |name| {
        rustix::fs::linkat(CWD, source.as_str(), CWD, name, AtFlags::SYMLINK_FOLLOW)
            .map_err(io::Error::from)
    })?;
    Ok(name)
}

#[cfg(not(any(target_os = "linux", target_os = "android")))]
fn link_unnamed(_: &File, _: &Path) -> io::Result<PathBuf> {
    Err(io::Error::other("unnamed files are not supported here"))
}

/// Removes the named temporary files in `dir` left by processes of this machine that
/// no longer run (killed with SIGKILL while writing where no unnamed file could be
/// made). Files of other machines (a shared file system) and of running processes
/// are left alone. Best effort: errors are ignored.
#[cfg(unix)]
fn remove_stale(dir: &Path) {
    let prefix = host_prefix();
    let own = std::process::id();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|name| name.strip_prefix(prefix.as_str()))
            .filter(|rest| rest.ends_with(".tmp"))
            .and_then(|rest| rest.split('-').next())
            .and_then(|pid| pid.parse::<i32>().ok())
        else {
            continue;
        };
        if pid as u32 == own {
            continue;
        }
        let dead = rustix::process::Pid::from_raw(pid).is_some_and(|pid| {
            rustix::process::test_kill_process(pid) == Err(rustix::io::Errno::SRCH)
        });
        if dead {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

#[cfg(not(unix))]
fn remove_stale(_: &Path) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_persisted_file_takes_the_place_and_leaves_nothing_else() {
        use std::io::Write;
        let dir = tempfile::tempdir().expect("tempdir");
        let target = dir.path().join("out.png");
        std::fs::write(&target, b"old").expect("write");
        let mut temporary = Temporary::create(&target, dir.path()).expect("create");
        temporary.file_mut().write_all(b"new").expect("write");
        temporary.persist(&target).expect("persist");
        assert_eq!(std::fs::read(&target).expect("read"), b"new");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, ["out.png"]);
    }

    #[test]
    fn a_discarded_file_leaves_nothing() {
        let dir = tempfile::tempdir().expect("tempdir");
        let target = dir.path().join("out.png");
        Temporary::create(&target, dir.path())
            .expect("create")
            .discard();
        assert_eq!(std::fs::read_dir(dir.path()).expect("list").count(), 0);
    }

    #[cfg(unix)]
    #[test]
    fn stale_files_of_dead_processes_of_this_machine_are_removed() {
        let dir = tempfile::tempdir().expect("tempdir");
        // A process that has ended: its id is free (until reused, which a test on a
        // quiet machine does not meet within milliseconds).
        let mut child = std::process::Command::new("true").spawn().expect("spawn");
        let dead = child.id();
        child.wait().expect("wait");
        let host = host_prefix();
        let stale = dir.path().join(format!("{host}{dead}-abcdef.tmp"));
        let running = dir
            .path()
            .join(format!("{host}{}-abcdef.tmp", std::process::id()));
        let elsewhere = dir
            .path()
            .join(format!(".gpu-render-another.host-{dead}-abcdef.tmp"));
        let unrelated = dir.path().join("notes.tmp");
        for path in [&stale, &running, &elsewhere, &unrelated] {
            std::fs::write(path, b"x").expect("write");
        }
        remove_stale(dir.path());
        assert!(!stale.exists(), "a dead process's file stays");
        assert!(running.exists() && elsewhere.exists() && unrelated.exists());
    }
}
