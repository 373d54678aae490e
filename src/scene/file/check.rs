//! Building blocks of validation: turning byte offsets into line:column, and checking
//! single fields (finite numbers, vectors, colours) of a named item.
//!
//! An item keeps only the byte offset where it begins; its line and column are worked
//! out when an error is reported, so loading stays linear in the size of the file
//! however many items it has.

use std::fmt::Display;
use std::ops::Range;
use std::path::Path;

use glam::DVec3;

use super::raw::{RawColor, RawVec3};
use crate::echo::short;
use crate::scene::{ImageError, MAX_RADIANCE, SceneError, SceneWarning};

/// The scene text and its path, for building located errors.
pub struct Source<'a> {
    /// The file named in errors.
    pub path: &'a Path,
    /// The whole scene text.
    pub text: &'a str,
}

impl<'a> Source<'a> {
    /// 1-based line and column (in characters) of byte `offset`. Linear in `offset`:
    /// call it for an error being reported, not for every item.
    pub fn location(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        let before = &self.text.as_bytes()[..offset];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
        let column = self
            .text
            .get(line_start..offset)
            .map_or(offset - line_start, |s| s.chars().count());
        (line, column + 1)
    }

    /// An error at `location`.
    pub fn error(
        &self,
        location: Option<(usize, usize)>,
        message: impl Into<String>,
    ) -> SceneError {
        SceneError::invalid(self.path, location, message)
    }

    /// A named item whose text starts at `span` (or has no place in the file).
    pub fn item(&self, name: String, span: Option<Range<usize>>) -> Item<'_> {
        Item {
            source: self,
            name,
            offset: span.map(|s| s.start),
        }
    }
}

/// Which values a colour may take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColourRange {
    /// A fraction of light reflected or transmitted: each channel in [0, 1].
    Fraction,
    /// Emitted light: each channel >= 0.
    Radiance,
}

/// One item of the scene (a table, a material, a light, an object) being checked:
/// every error it makes names it and points at where it begins.
pub struct Item<'a> {
    source: &'a Source<'a>,
    name: String,
    /// Byte offset where the item begins in the file, if it has a place there.
    offset: Option<usize>,
}

impl Item<'_> {
    /// The error `"{item}: {message}"` at the item's place.
    pub fn fail(&self, message: impl Display) -> SceneError {
        let location = self.offset.map(|offset| self.source.location(offset));
        self.source
            .error(location, format!("{}: {message}", self.name))
    }

    /// The error `"{item}: {what}: {error}"` at the item's place, for an image the
    /// item names that was refused ([`SceneError::Image`], `error` its source).
    pub fn fail_image(&self, what: impl Display, error: ImageError) -> SceneError {
        SceneError::Image {
            path: self.source.path.to_path_buf(),
            location: self.offset.map(|offset| self.source.location(offset)),
            message: format!("{}: {what}: {error}", self.name),
            source: error,
        }
    }

    /// The warning `"{item}: {message}"` at the item's place.
    pub fn warning(&self, message: impl Display) -> SceneWarning {
        let location = self.offset.map(|offset| self.source.location(offset));
        SceneWarning {
            path: self.source.path.to_path_buf(),
            location,
            message: format!("{}: {message}", self.name),
        }
    }

    /// The value of a required field, or an error naming it.
    pub fn require<T>(&self, field: &str, value: Option<T>) -> Result<T, SceneError> {
        value.ok_or_else(|| self.fail(format_args!("missing required field `{field}`")))
    }

    /// Rejects fields that exist in the format but not for this item's `kind`.
    pub fn only_fields(
        &self,
        kind: &str,
        allowed: &[&str],
        given: &[&str],
    ) -> Result<(), SceneError> {
        match given.iter().find(|field| !allowed.contains(field)) {
            Some(field) => {
                let article = if kind.starts_with(['a', 'e', 'i', 'o', 'u']) {
                    "an"
                } else {
                    "a"
                };
                Err(self.fail(format_args!(
                    "{article} {kind} has no field `{field}` (it takes: {})",
                    allowed.join(", ")
                )))
            }
            None => Ok(()),
        }
    }

    /// A finite number that the GPU's 32-bit floats represent as a normal number (or
    /// 0): the CPU reference works in f64, and a value that became 0 or infinity on
    /// upload would make the two backends disagree silently.
    pub fn number(&self, field: &str, value: f64) -> Result<f64, SceneError> {
        if let Some(what) = non_finite(value) {
            return Err(self.fail(format_args!("{field} is {what}")));
        }
        if value.abs() > f64::from(f32::MAX) {
            return Err(self.fail(format_args!(
                "{field} = {value:e} is too large for 32-bit floats (|x| <= 3.4e38)"
            )));
        }
        if value != 0.0 && value.abs() < f64::from(f32::MIN_POSITIVE) {
            return Err(self.fail(format_args!(
                "{field} = {value:e} is too small for 32-bit floats (0, or |x| >= 1.2e-38)"
            )));
        }
        Ok(value)
    }

    /// A finite number >= 0.
    pub fn non_negative(&self, field: &str, value: f64) -> Result<f64, SceneError> {
        let value = self.number(field, value)?;
        if value < 0.0 {
            return Err(self.fail(format_args!("{field} must be >= 0, got {}", short(value))));
        }
        Ok(value)
    }

    /// A vector of finite components.
    pub fn vector(&self, field: &str, value: RawVec3) -> Result<DVec3, SceneError> {
        for (axis, component) in ["x", "y", "z"].iter().zip(value) {
            self.number(&format!("{field}.{axis}"), component)?;
        }
        Ok(DVec3::from_array(value))
    }

    /// A colour whose channels are finite and within `range`.
    pub fn colour(
        &self,
        field: &str,
        value: RawColor,
        range: ColourRange,
    ) -> Result<DVec3, SceneError> {
        match value {
            RawColor::Grey(grey) => self.channel(field, grey, range).map(DVec3::splat),
            RawColor::Rgb(rgb) => {
                for (name, channel) in ["r", "g", "b"].iter().zip(rgb) {
                    self.channel(&format!("{field}.{name}"), channel, range)?;
                }
                Ok(DVec3::from_array(rgb))
            }
        }
    }

    /// An optional colour, `default` when absent.
    pub fn colour_or(
        &self,
        field: &str,
        value: Option<RawColor>,
        range: ColourRange,
        default: DVec3,
    ) -> Result<DVec3, SceneError> {
        value.map_or(Ok(default), |c| self.colour(field, c, range))
    }

    fn channel(&self, field: &str, value: f64, range: ColourRange) -> Result<f64, SceneError> {
        let value = self.number(field, value)?;
        let ok = match range {
            ColourRange::Fraction => (0.0..=1.0).contains(&value),
            ColourRange::Radiance => (0.0..=MAX_RADIANCE).contains(&value),
        };
        if !ok {
            let accepted = match range {
                ColourRange::Fraction => "in [0, 1]",
                ColourRange::Radiance if value >= 0.0 => {
                    "at most 1e30 (the GPU sums radiance in 32-bit floats)"
                }
                ColourRange::Radiance => ">= 0",
            };
            return Err(self.fail(format_args!(
                "{field} must be {accepted}, got {}",
                short(value)
            )));
        }
        Ok(value)
    }
}

/// How a non-finite number is described, or `None` for a finite one.
fn non_finite(value: f64) -> Option<&'static str> {
    if value.is_nan() {
        Some("NaN")
    } else if value == f64::INFINITY {
        Some("infinite (inf)")
    } else if value == f64::NEG_INFINITY {
        Some("infinite (-inf)")
    } else {
        None
    }
}
