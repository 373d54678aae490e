//! Resolving the files a scene names (textures, BRDF maps, and later model files),
//! relative to the scene file's folder, optionally confined to it.

use std::path::{Component, Path, PathBuf};

use crate::echo::echo_path;

/// Why a sandboxed scene's file name was refused ([`confined_path`]). The messages name
/// the file as the scene wrote it (without the scene's path, which the caller names).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SandboxError {
    /// The name is an absolute path.
    #[error("`{}` is an absolute path; a sandboxed scene may only name files inside its folder", echo_path(.0))]
    Absolute(PathBuf),
    /// The name contains `..`.
    #[error("`{}` contains `..`; a sandboxed scene may only name files inside its folder", echo_path(.0))]
    ParentDir(PathBuf),
    /// The name has a drive prefix or root.
    #[error("`{}` names a drive or root; a sandboxed scene may only name files inside its folder", echo_path(.0))]
    Root(PathBuf),
    /// A symbolic link inside the folder leads out of it.
    #[error(
        "`{}` leads out of the scene's folder (to {}) through a symbolic link; \
         a sandboxed scene may only name files inside its folder",
        echo_path(.file),
        echo_path(.resolved)
    )]
    LinkOutside {
        /// The name as the scene wrote it.
        file: PathBuf,
        /// Where the link leads.
        resolved: PathBuf,
    },
}

/// The path of `file`, as a scene file in folder `scene_dir` names it, confined to that
/// folder: `file` must be relative, must not contain `..` (or a drive or root), and
/// must not lead out of `scene_dir` through a symbolic link. Returns the joined path
/// (`scene_dir/file`), or why the file is refused.
///
/// This is the `--sandbox` rule: without it a scene file is trusted input, like a
/// program, and may name any file the user can read.
///
/// ```
/// use std::path::Path;
/// use gpu_render::scene::{SandboxError, confined_path};
/// assert!(confined_path(Path::new("scenes"), "textures/wood.png").is_ok());
/// assert!(matches!(
///     confined_path(Path::new("scenes"), "../secret.png"),
///     Err(SandboxError::ParentDir(_))
/// ));
/// assert!(confined_path(Path::new("scenes"), "/etc/passwd").is_err());
/// ```
pub fn confined_path(scene_dir: &Path, file: &str) -> Result<PathBuf, SandboxError> {
    let relative = Path::new(file);
    if relative.is_absolute() || relative.has_root() {
        return Err(SandboxError::Absolute(relative.to_path_buf()));
    }
    for component in relative.components() {
        match component {
            Component::ParentDir => return Err(SandboxError::ParentDir(relative.to_path_buf())),
            Component::Prefix(_) | Component::RootDir => {
                return Err(SandboxError::Root(relative.to_path_buf()));
            }
            Component::CurDir | Component::Normal(_) => {}
        }
    }
    let joined = scene_dir.join(relative);
    // A symbolic link inside the folder may still point out of it. A file that does
    // not exist cannot be resolved; reading it fails later with the OS's reason.
    let base = if scene_dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        scene_dir
    };
    if let (Ok(resolved), Ok(base)) = (joined.canonicalize(), base.canonicalize())
        && !resolved.starts_with(&base)
    {
        return Err(SandboxError::LinkOutside {
            file: relative.to_path_buf(),
            resolved,
        });
    }
    Ok(joined)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_relative_paths_are_joined() {
        let dir = Path::new("scenes");
        assert_eq!(
            confined_path(dir, "textures/wood.png"),
            Ok(PathBuf::from("scenes/textures/wood.png"))
        );
        assert_eq!(
            confined_path(dir, "./wood.png"),
            Ok(PathBuf::from("scenes/./wood.png"))
        );
    }

    #[test]
    fn escapes_are_refused() {
        let dir = Path::new("scenes");
        for (file, why) in [
            ("/etc/passwd", "absolute"),
            ("../secret.png", "`..`"),
            ("textures/../../secret.png", "`..`"),
        ] {
            let err = confined_path(dir, file).expect_err(file).to_string();
            assert!(err.contains(why) && err.contains(file), "{err}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_link_out_of_the_folder_is_refused() {
        let outside = tempfile::tempdir().expect("tempdir");
        let secret = outside.path().join("secret.png");
        std::fs::write(&secret, b"x").expect("write");
        let scene_dir = tempfile::tempdir().expect("tempdir");
        std::os::unix::fs::symlink(&secret, scene_dir.path().join("innocent.png"))
            .expect("symlink");
        std::fs::write(scene_dir.path().join("inside.png"), b"x").expect("write");
        let err = confined_path(scene_dir.path(), "innocent.png").expect_err("escapes");
        assert!(matches!(err, SandboxError::LinkOutside { .. }), "{err}");
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert!(confined_path(scene_dir.path(), "inside.png").is_ok());
    }
}
