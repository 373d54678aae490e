//! Errors about scene files: each names the file, the place and the problem.

use std::fmt;
use std::path::{Path, PathBuf};

use crate::echo::escape_controls;

/// A problem with a scene file: unreadable, malformed, or describing an impossible scene.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct SceneError {
    /// The scene file (or a placeholder such as `<string>` for text parsed from memory).
    pub path: PathBuf,
    /// 1-based line and column of the offending item, where known.
    pub location: Option<(usize, usize)>,
    /// What is wrong, naming the field or item.
    pub message: String,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        located(f, &self.path, self.location, &self.message)
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
