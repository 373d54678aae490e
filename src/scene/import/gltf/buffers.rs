//! The model's buffers: the GLB binary chunk, data URIs (RFC 2397) and files relative
//! to the model, each counted against the import's budget.

use std::path::{Path, PathBuf};

use ::gltf::Document;
use base64::Engine;

use crate::scene::SceneError;
use crate::scene::import::mesh::Budget;
use crate::scene::import::{error, read_file};

/// A data URI's bytes (RFC 2397), base64 or percent-encoded.
pub(super) fn data_uri(uri: &str) -> Option<Result<Vec<u8>, String>> {
    let rest = uri.strip_prefix("data:")?;
    let Some((header, data)) = rest.split_once(',') else {
        return Some(Err("the data URI has no ',' before its data".into()));
    };
    Some(if header.ends_with(";base64") {
        let engine = base64::engine::GeneralPurpose::new(
            &base64::alphabet::STANDARD,
            base64::engine::GeneralPurposeConfig::new()
                .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
        );
        engine
            .decode(data.trim())
            .map_err(|e| format!("the data URI is not valid base64: {e}"))
    } else {
        Ok(percent_decode(data))
    })
}

/// Undoes URI percent-encoding (`%20` → space); malformed escapes stay as they are.
pub(super) fn percent_decode(text: &str) -> Vec<u8> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    out
}

/// The file a relative URI names, or why it names none.
pub(super) fn uri_file(directory: &Path, uri: &str) -> Result<PathBuf, String> {
    let scheme = uri.split_once(':').map(|(s, _)| s);
    if scheme.is_some_and(|s| {
        s.len() > 1
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
    }) {
        return Err(format!(
            "the URI {uri} is neither a relative file path nor a data URI (nothing is fetched from the network)"
        ));
    }
    let decoded = String::from_utf8_lossy(&percent_decode(uri)).into_owned();
    Ok(directory.join(decoded))
}

/// Loads every buffer: the GLB binary chunk, a data URI or a file relative to the model.
pub(super) fn load_buffers(
    document: &Document,
    blob: Option<&[u8]>,
    path: &Path,
    directory: &Path,
    budget: &mut Budget,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let name = match buffer.name() {
            Some(name) => format!("buffer {} ('{name}')", buffer.index()),
            None => format!("buffer {}", buffer.index()),
        };
        let fail = |message: String| error(path, format!("{name}: {message}"));
        let data = match buffer.source() {
            ::gltf::buffer::Source::Bin => blob
                .ok_or_else(|| {
                    fail("refers to the GLB binary chunk, but the file has none".into())
                })?
                .to_vec(),
            ::gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(decoded) => {
                    let bytes = decoded.map_err(fail)?;
                    budget
                        .charge_bytes(bytes.len() as u64, &name)
                        .map_err(|e| e.at(path))?;
                    bytes
                }
                None => {
                    let file = uri_file(directory, uri).map_err(fail)?;
                    read_file(&file, path, &format!("{name} {}", file.display()), budget)?
                }
            },
        };
        if data.len() < buffer.length() {
            return Err(fail(format!(
                "holds {} bytes, fewer than its byteLength {} (truncated?)",
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_uris_and_percent_escapes_decode() {
        assert_eq!(
            data_uri("data:application/octet-stream;base64,AAEC").map(Result::ok),
            Some(Some(vec![0, 1, 2]))
        );
        assert_eq!(
            data_uri("data:application/octet-stream;base64,AAE").map(Result::ok),
            Some(Some(vec![0, 1]))
        );
        assert!(data_uri("data:;base64,!!").is_some_and(|r| r.is_err()));
        assert!(data_uri("buffer.bin").is_none());
        assert_eq!(percent_decode("my%20file.bin"), b"my file.bin");
        assert_eq!(percent_decode("100%"), b"100%");
        assert_eq!(percent_decode("%4"), b"%4");
    }

    #[test]
    fn only_relative_uris_name_files() {
        let dir = Path::new("models");
        assert_eq!(
            uri_file(dir, "tex%201.png"),
            Ok(PathBuf::from("models/tex 1.png"))
        );
        assert!(uri_file(dir, "https://example.com/a.bin").is_err());
        assert!(uri_file(dir, "file:///etc/passwd").is_err());
    }
}
