//! Opening the files a render reads (scene files, textures, environment maps, models,
//! material libraries, buffers, tiles), so that no input can hang or escape the rules.
//!
//! Every input is opened first and judged on what was opened (`fstat` on the open
//! descriptor), never on a path looked up before: a FIFO, a device or a directory is
//! refused at once, whatever link leads to it, and nothing can be swapped in between
//! the check and the read. Opening never blocks: a FIFO is opened without waiting for
//! a writer (`O_NONBLOCK`), then refused.
//!
//! A sandboxed scene's files are opened relative to a descriptor of the scene's folder
//! with the kernel resolving the path beneath it (Linux `openat2` with
//! `RESOLVE_BENEATH`, so that the confinement and the open are one step; elsewhere on
//! Unix, and where `openat2` is not allowed, component by component with
//! `O_NOFOLLOW`, which refuses every symbolic link).
//!
//! Every file opened here is noted, by its identity on disk (device and inode, taken
//! from the open descriptor), for whoever asked with [`record_inputs`]: a program
//! refuses an output that is one of them, whatever name led to it and however the
//! loader used it (a material library, a buffer, a texture merged into another or read
//! and dropped).

use std::cell::RefCell;
use std::fs::File;
use std::io::{self, Read};
use std::path::{Component, Path, PathBuf};

/// Why an input file cannot be read. The messages are the reason alone, without the
/// file's path, which the caller names with the file's role: "cannot read the model
/// file: {reason}".
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputError {
    /// The operating system refused to open or read it (missing, no permission, ...).
    #[error("{0}")]
    Io(#[source] io::Error),
    /// It is not a regular file: reading a FIFO or a device would block or never end.
    #[error("it is {kind}, not a regular file")]
    NotARegularFile {
        /// What it is ("a FIFO", "a device", "a directory", "a socket").
        kind: &'static str,
    },
    /// It is larger than the reader accepts.
    #[error("it is {bytes} bytes, more than the {limit} accepted ({} MiB)", limit / (1024 * 1024))]
    TooLarge {
        /// Its size (or as much of it as was read).
        bytes: u64,
        /// The largest size accepted.
        limit: u64,
    },
    /// A sandboxed scene named a file outside its folder, or reached one through a
    /// symbolic link that leads out of it.
    #[error(
        "it leads out of the scene's folder{how}; a sandboxed scene may only name files inside its folder"
    )]
    OutsideFolder {
        /// How (" through a symbolic link", or nothing).
        how: &'static str,
    },
}

/// Opens `path` for reading, following links, and returns it only if it is a regular
/// file: a FIFO is refused without waiting for a writer, a device or directory
/// without reading from it.
pub fn open_input(path: &Path) -> Result<File, InputError> {
    let file = open_nonblocking(path).map_err(InputError::Io)?;
    check_regular(file, path)
}

/// Reads the whole regular file at `path`, refusing one larger than `limit` bytes
/// (by its size before reading, and again by what was read, in case it grew).
pub fn read_input(path: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    read_limited(open_input(path)?, limit)
}

/// Opens `relative` (a path a sandboxed scene names, already checked to be relative
/// and free of `..`) inside the folder `dir`, so that neither a symbolic link nor a
/// swap of one during the open reaches a file outside `dir`; then as [`open_input`].
pub fn open_confined(dir: &Path, relative: &Path) -> Result<File, InputError> {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    if relative
        .components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err(InputError::OutsideFolder { how: "" });
    }
    let file = confined::open(dir, relative)?;
    check_regular(file, &dir.join(relative))
}

/// Reads the whole file `relative` inside `dir` as [`open_confined`] opens it,
/// refusing one larger than `limit` bytes.
pub fn read_confined(dir: &Path, relative: &Path, limit: u64) -> Result<Vec<u8>, InputError> {
    read_limited(open_confined(dir, relative)?, limit)
}

/// Reads the whole of `file` (opened by [`open_input`] or [`open_confined`]),
/// refusing one larger than `limit` bytes.
pub fn read_opened(file: File, limit: u64) -> Result<Vec<u8>, InputError> {
    read_limited(file, limit)
}

fn read_limited(file: File, limit: u64) -> Result<Vec<u8>, InputError> {
    let len = file.metadata().map_err(InputError::Io)?.len();
    if len > limit {
        return Err(InputError::TooLarge { bytes: len, limit });
    }
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(InputError::Io)?;
    if bytes.len() as u64 > limit {
        return Err(InputError::TooLarge {
            bytes: bytes.len() as u64,
            limit,
        });
    }
    Ok(bytes)
}

/// `file` (opened as `path`) if the open descriptor is a regular file (`fstat`, so no
/// later swap counts), noted for [`record_inputs`].
fn check_regular(file: File, path: &Path) -> Result<File, InputError> {
    let metadata = file.metadata().map_err(InputError::Io)?;
    match not_a_regular_file(&metadata) {
        None => {
            note_input(path, &metadata);
            Ok(file)
        }
        Some(kind) => Err(InputError::NotARegularFile { kind }),
    }
}

/// A file that was opened as an input: the name it was opened by and its identity on
/// disk when it was opened.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputFile {
    /// The path it was opened by (as the scene or model named it, joined to its folder).
    pub path: PathBuf,
    /// Its identity: device and inode on Unix, the resolved path elsewhere.
    pub identity: FileIdentity,
}

/// Which file on disk a path reaches, whatever links or spellings lead to it.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct FileIdentity(IdentityKey);

#[cfg(unix)]
type IdentityKey = (u64, u64);
#[cfg(not(unix))]
type IdentityKey = PathBuf;

impl FileIdentity {
    /// The identity of the file `metadata` describes (reached as `path`).
    #[cfg(unix)]
    pub fn of(metadata: &std::fs::Metadata, _path: &Path) -> Self {
        use std::os::unix::fs::MetadataExt;
        Self((metadata.dev(), metadata.ino()))
    }

    /// The identity of the file `metadata` describes (reached as `path`).
    #[cfg(not(unix))]
    pub fn of(_metadata: &std::fs::Metadata, path: &Path) -> Self {
        Self(path.canonicalize().unwrap_or_else(|_| path.to_path_buf()))
    }

    /// The identity of the file at `path` now (links followed), if it exists.
    pub fn at(path: &Path) -> Option<Self> {
        std::fs::metadata(path)
            .ok()
            .map(|metadata| Self::of(&metadata, path))
    }
}

thread_local! {
    /// The inputs opened on this thread, one list per [`record_inputs`] call in progress
    /// (innermost last).
    static RECORDINGS: RefCell<Vec<Vec<InputFile>>> = const { RefCell::new(Vec::new()) };
}

/// Runs `load` and returns, with its result, every input file it opened on this thread
/// through this module (scene files, images, models, material libraries, buffers,
/// tiles), each once, in the order first opened: files that failed to load count too,
/// as long as they were opened. Calls may nest; an inner call's files are the outer
/// call's too.
pub fn record_inputs<T>(load: impl FnOnce() -> T) -> (T, Vec<InputFile>) {
    RECORDINGS.with(|recordings| recordings.borrow_mut().push(Vec::new()));
    /// Pops this call's list even if `load` panics, so no later call sees it.
    struct Pop;
    impl Drop for Pop {
        fn drop(&mut self) {
            RECORDINGS.with(|recordings| {
                let mut recordings = recordings.borrow_mut();
                if let Some(inner) = recordings.pop()
                    && let Some(outer) = recordings.last_mut()
                {
                    for file in inner {
                        if !outer.contains(&file) {
                            outer.push(file);
                        }
                    }
                }
            });
        }
    }
    let pop = Pop;
    let result = load();
    let files =
        RECORDINGS.with(|recordings| recordings.borrow().last().cloned().unwrap_or_default());
    drop(pop);
    (result, files)
}

/// Notes the input `path` (described by `metadata`) for the [`record_inputs`] calls in
/// progress on this thread.
fn note_input(path: &Path, metadata: &std::fs::Metadata) {
    RECORDINGS.with(|recordings| {
        if let Some(files) = recordings.borrow_mut().last_mut() {
            let file = InputFile {
                path: path.to_path_buf(),
                identity: FileIdentity::of(metadata, path),
            };
            if !files.contains(&file) {
                files.push(file);
            }
        }
    });
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    // O_NONBLOCK: opening a FIFO for reading does not wait for a writer. It changes
    // nothing for regular files, the only ones read afterwards.
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(rustix::fs::OFlags::NONBLOCK.bits() as i32)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    File::open(path)
}

/// What a file that is not a regular file is ("a directory", "a FIFO", "a device",
/// "a socket"), or `None` for a regular file.
pub(crate) fn not_a_regular_file(metadata: &std::fs::Metadata) -> Option<&'static str> {
    if metadata.is_file() {
        return None;
    }
    if metadata.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let kind = metadata.file_type();
        if kind.is_fifo() {
            return Some("a FIFO");
        }
        if kind.is_char_device() || kind.is_block_device() {
            return Some("a device");
        }
        if kind.is_socket() {
            return Some("a socket");
        }
    }
    Some("a special file")
}

#[cfg(unix)]
mod confined {
    //! The confined open: the kernel resolves the path beneath the folder.

    use std::fs::File;
    use std::io;
    use std::path::{Component, Path};

    use rustix::fs::{Mode, OFlags};
    use rustix::io::Errno;

    use super::InputError;

    pub(super) fn open(dir: &Path, relative: &Path) -> Result<File, InputError> {
        let flags = OFlags::RDONLY | OFlags::NONBLOCK | OFlags::CLOEXEC;
        let folder = rustix::fs::open(
            dir,
            OFlags::RDONLY | OFlags::DIRECTORY | OFlags::CLOEXEC,
            Mode::empty(),
        )
        .map_err(|e| InputError::Io(e.into()))?;
        #[cfg(any(target_os = "linux", target_os = "android"))]
        {
            use rustix::fs::ResolveFlags;
            match rustix::fs::openat2(
                &folder,
                relative,
                flags,
                Mode::empty(),
                ResolveFlags::BENEATH | ResolveFlags::NO_MAGICLINKS,
            ) {
                Ok(fd) => return Ok(File::from(fd)),
                // EXDEV: the resolution would leave the folder (through a link).
                Err(Errno::XDEV) => {
                    return Err(InputError::OutsideFolder {
                        how: " through a symbolic link",
                    });
                }
                // An older kernel, or a seccomp filter that forbids openat2: walk.
                Err(Errno::NOSYS | Errno::PERM) => {}
                Err(e) => return Err(InputError::Io(e.into())),
            }
        }
        walk(folder, relative, flags)
    }

    /// Opens `relative` beneath `folder` one component at a time, none of them
    /// followed if it is a symbolic link: a link anywhere on the path is refused.
    fn walk(
        folder: rustix::fd::OwnedFd,
        relative: &Path,
        flags: OFlags,
    ) -> Result<File, InputError> {
        let names: Vec<_> = relative
            .components()
            .filter_map(|c| match c {
                Component::Normal(name) => Some(name),
                _ => None,
            })
            .collect();
        let Some((last, parents)) = names.split_last() else {
            return Err(InputError::Io(io::Error::new(
                io::ErrorKind::InvalidInput,
                "the path names no file",
            )));
        };
        let refuse_link = |e: Errno| match e {
            Errno::LOOP | Errno::NOTDIR => InputError::OutsideFolder {
                how: " through a symbolic link (links are not followed in a sandbox here)",
            },
            e => InputError::Io(e.into()),
        };
        let mut current = folder;
        for name in parents {
            current = rustix::fs::openat(
                &current,
                *name,
                OFlags::RDONLY | OFlags::DIRECTORY | OFlags::NOFOLLOW | OFlags::CLOEXEC,
                Mode::empty(),
            )
            .map_err(refuse_link)?;
        }
        rustix::fs::openat(&current, *last, flags | OFlags::NOFOLLOW, Mode::empty())
            .map(File::from)
            .map_err(refuse_link)
    }
}

#[cfg(not(unix))]
mod confined {
    //! Without descriptor-relative opens the check and the open are two steps: the
    //! resolved path must lie in the folder, then it is opened.

    use std::fs::File;
    use std::path::Path;

    use super::InputError;

    pub(super) fn open(dir: &Path, relative: &Path) -> Result<File, InputError> {
        let joined = dir.join(relative);
        let resolved = joined.canonicalize().map_err(InputError::Io)?;
        let base = dir.canonicalize().map_err(InputError::Io)?;
        if !resolved.starts_with(&base) {
            return Err(InputError::OutsideFolder {
                how: " through a symbolic link",
            });
        }
        super::open_nonblocking(&resolved).map_err(InputError::Io)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_regular_file_is_read_and_limited() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("a.txt");
        std::fs::write(&path, b"12345").expect("write");
        assert_eq!(read_input(&path, 5).expect("fits"), b"12345");
        let err = read_input(&path, 4).expect_err("too large");
        assert!(
            matches!(err, InputError::TooLarge { bytes: 5, limit: 4 }),
            "{err}"
        );
    }

    #[test]
    fn a_directory_is_refused() {
        let dir = tempfile::tempdir().expect("tempdir");
        let err = read_input(dir.path(), 10).expect_err("a directory");
        assert!(err.to_string().contains("a directory"), "{err}");
    }

    #[cfg(unix)]
    #[test]
    fn a_device_behind_a_link_is_refused_without_reading() {
        let dir = tempfile::tempdir().expect("tempdir");
        let link = dir.path().join("zero.obj");
        std::os::unix::fs::symlink("/dev/zero", &link).expect("symlink");
        let started = std::time::Instant::now();
        let err = read_input(&link, u64::MAX).expect_err("a device");
        assert!(err.to_string().contains("a device"), "{err}");
        assert!(started.elapsed().as_secs() < 5, "refused at once");
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_waiting_for_a_writer() {
        let dir = tempfile::tempdir().expect("tempdir");
        let fifo = dir.path().join("model.obj");
        rustix::fs::mkfifoat(
            rustix::fs::CWD,
            &fifo,
            rustix::fs::Mode::RUSR | rustix::fs::Mode::WUSR,
        )
        .expect("mkfifo");
        // A blocking open would never return: the test would hang, not fail.
        let err = read_input(&fifo, 100).expect_err("a FIFO");
        assert!(err.to_string().contains("a FIFO"), "{err}");
        let err = read_confined(dir.path(), Path::new("model.obj"), 100).expect_err("a FIFO");
        assert!(err.to_string().contains("a FIFO"), "{err}");
    }

    #[cfg(unix)]
    #[test]
    fn a_confined_open_stays_in_the_folder() {
        let outside = tempfile::tempdir().expect("tempdir");
        std::fs::write(outside.path().join("secret.png"), b"secret").expect("write");
        let scene = tempfile::tempdir().expect("tempdir");
        std::fs::create_dir(scene.path().join("textures")).expect("mkdir");
        std::fs::write(scene.path().join("textures/wood.png"), b"wood").expect("write");
        std::os::unix::fs::symlink(
            outside.path().join("secret.png"),
            scene.path().join("textures/link.png"),
        )
        .expect("symlink");
        std::os::unix::fs::symlink(outside.path(), scene.path().join("out")).expect("symlink");
        let read = |name: &str| read_confined(scene.path(), Path::new(name), 100);
        assert_eq!(read("textures/wood.png").expect("inside"), b"wood");
        assert_eq!(read("./textures/wood.png").expect("inside"), b"wood");
        for escape in [
            "textures/link.png",
            "out/secret.png",
            "../secret.png",
            "/etc/passwd",
        ] {
            let err = read(escape).expect_err(escape);
            assert!(
                matches!(err, InputError::OutsideFolder { .. }),
                "{escape}: {err}"
            );
        }
    }
}
