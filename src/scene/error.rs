//! Errors about scene files: each names the file, the place and the problem.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::ImageError;
use crate::echo::escape_controls;
use crate::input::InputError;

/// A problem with a scene or model file: unreadable, malformed, unsupported, too large,
/// or describing an impossible scene. Every variant names the file, the 1-based
/// line and column where known, and the problem; `Display` writes them as
/// `path:line:column: message` on one line.
///
/// Non-exhaustive: match the variants you handle and keep a catch-all arm. The
/// accessors [`SceneError::path`], [`SceneError::location`] and
/// [`SceneError::message`] work for every variant.
///
/// ```
/// use gpu_render::low_level::input::InputError;
/// use gpu_render::scene::{SceneError, load_scene};
/// match load_scene(std::path::Path::new("no/such/scene.toml")) {
///     Err(SceneError::Read { source, .. }) => match &*source {
///         InputError::Io(e) => assert_eq!(e.kind(), std::io::ErrorKind::NotFound),
///         other => panic!("expected the OS's error, got {other}"),
///     },
///     other => panic!("expected a read error, got {other:?}"),
/// }
/// ```
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum SceneError {
    /// A file (the scene, a model, a material library, a buffer) could not be opened
    /// or read: missing, a folder, not permitted, not a regular file, larger than its
    /// reader accepts. The [`InputError`] is the [`source`](std::error::Error::source).
    Read {
        /// The file.
        path: PathBuf,
        /// What could not be read, with the I/O error's words.
        message: String,
        /// Why it could not be read.
        source: Arc<InputError>,
    },
    /// The file is not well-formed in its format (TOML, glTF's JSON or GLB container,
    /// UTF-8).
    Syntax {
        /// The file.
        path: PathBuf,
        /// 1-based line and column, where known.
        location: Option<(usize, usize)>,
        /// What the parser found.
        message: String,
    },
    /// The file is well-formed but describes something impossible or out of range: a
    /// value outside its range, an undefined name, a degenerate shape.
    Invalid {
        /// The file.
        path: PathBuf,
        /// 1-based line and column of the item, where known.
        location: Option<(usize, usize)>,
        /// What is wrong, naming the field or item.
        message: String,
    },
    /// An image the file names (a texture, a BRDF map, an environment map) could not
    /// be read or decoded. The [`ImageError`] is the
    /// [`source`](std::error::Error::source).
    Image {
        /// The file that names the image.
        path: PathBuf,
        /// 1-based line and column of the item that names it, where known.
        location: Option<(usize, usize)>,
        /// What is wrong, naming the item and the image.
        message: String,
        /// Why the image was refused.
        source: ImageError,
    },
    /// The file asks for something this program does not read (glTF 1.0, a required
    /// glTF extension it does not implement, a model format it does not know).
    Unsupported {
        /// The file.
        path: PathBuf,
        /// 1-based line and column, where known.
        location: Option<(usize, usize)>,
        /// What is not supported, and what to do instead where there is a way.
        message: String,
    },
    /// The file is larger than accepted, or holds more elements, vertices, texels or
    /// bytes than the limits and the memory budget allow.
    TooLarge {
        /// The file.
        path: PathBuf,
        /// 1-based line and column, where known.
        location: Option<(usize, usize)>,
        /// Which limit, and by how much.
        message: String,
    },
}

/// Constructors of the variants that hold a path, a location and a message.
macro_rules! located_constructors {
    ($($name:ident => $variant:ident),* $(,)?) => {$(
        #[doc = concat!("A [`SceneError::", stringify!($variant), "`] at `location` of `path`.")]
        pub fn $name(
            path: impl Into<PathBuf>,
            location: Option<(usize, usize)>,
            message: impl Into<String>,
        ) -> Self {
            Self::$variant {
                path: path.into(),
                location,
                message: message.into(),
            }
        }
    )*};
}

impl SceneError {
    located_constructors!(
        invalid => Invalid,
        syntax => Syntax,
        unsupported => Unsupported,
        too_large => TooLarge,
    );

    /// A [`SceneError::Read`] of `path`: `what` (such as "cannot read the scene file")
    /// followed by the I/O error's words.
    pub fn read(path: impl Into<PathBuf>, what: impl fmt::Display, source: InputError) -> Self {
        Self::Read {
            path: path.into(),
            message: format!("{what}: {source}"),
            source: Arc::new(source),
        }
    }

    /// The file the error is about (or a placeholder such as `<string>` for text
    /// parsed from memory).
    pub fn path(&self) -> &Path {
        match self {
            Self::Read { path, .. }
            | Self::Syntax { path, .. }
            | Self::Invalid { path, .. }
            | Self::Image { path, .. }
            | Self::Unsupported { path, .. }
            | Self::TooLarge { path, .. } => path,
        }
    }

    /// 1-based line and column of the offending item, where known.
    pub fn location(&self) -> Option<(usize, usize)> {
        match self {
            Self::Read { .. } => None,
            Self::Syntax { location, .. }
            | Self::Invalid { location, .. }
            | Self::Image { location, .. }
            | Self::Unsupported { location, .. }
            | Self::TooLarge { location, .. } => *location,
        }
    }

    /// What is wrong, without the path and location.
    pub fn message(&self) -> &str {
        match self {
            Self::Read { message, .. }
            | Self::Syntax { message, .. }
            | Self::Invalid { message, .. }
            | Self::Image { message, .. }
            | Self::Unsupported { message, .. }
            | Self::TooLarge { message, .. } => message,
        }
    }

    /// The same error with its message prefixed by `prefix` (an item's name, the file
    /// that included this one), its kind, place and source kept.
    pub fn prefixed(mut self, prefix: impl fmt::Display) -> Self {
        let message = match &mut self {
            Self::Read { message, .. }
            | Self::Syntax { message, .. }
            | Self::Invalid { message, .. }
            | Self::Image { message, .. }
            | Self::Unsupported { message, .. }
            | Self::TooLarge { message, .. } => message,
        };
        *message = format!("{prefix}{message}");
        self
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        located(f, self.path(), self.location(), self.message())
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Read { source, .. } => Some(source.as_ref()),
            Self::Image { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// `path:line:column: message`, on one line: control characters that reached the path
/// or the message from a file (a name quoted whole, a parser's words) are escaped
/// ([`escape_controls`]).
fn located(
    f: &mut fmt::Formatter<'_>,
    path: &Path,
    location: Option<(usize, usize)>,
    message: &str,
) -> fmt::Result {
    let path = path.display().to_string();
    let (path, message) = (escape_controls(&path), escape_controls(message));
    match location {
        Some((line, column)) => write!(f, "{path}:{line}:{column}: {message}"),
        None => write!(f, "{path}: {message}"),
    }
}

/// Something suspicious in a scene file that was accepted anyway (and how), for example
/// an albedo texel above 1 that was clamped. Located like a [`SceneError`].
#[derive(Debug, Clone, PartialEq)]
pub struct SceneWarning {
    /// The scene file.
    pub path: PathBuf,
    /// 1-based line and column of the item concerned, where known.
    pub location: Option<(usize, usize)>,
    /// What was found and what was done about it.
    pub message: String,
}

impl fmt::Display for SceneWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        located(f, &self.path, self.location, &self.message)
    }
}
