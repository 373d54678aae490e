//! OpenEXR files with the render's auxiliary passes as layers beside the radiance: what
//! a denoiser (Intel Open Image Denoise, the built-in filter) and compositing tools
//! read (`--aov albedo,normal,depth`).
//!
//! Channels, sorted by name as OpenEXR wants: `R`, `G`, `B`, `A` (the linear
//! radiance), `albedo.R`, `albedo.G`, `albedo.B`, `normal.X`, `normal.Y`, `normal.Z`
//! (world space) and `depth.Z` (distance along the camera ray; 0 where it escapes), each
//! 32-bit float, for the passes asked for. Compression: ZIP of 16 rows (lossless).

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, ImageAttributes, IntegerBounds, Layer,
    LayerAttributes, SmallVec, Text, Vec2,
};

use super::{OutputError, write_bytes};
use crate::denoise::GuidePasses;
use crate::film::LinearImage;

/// An auxiliary pass a render can write beside its radiance (`--aov`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum AuxPass {
    /// First-hit albedo after textures, in [0, 1] (`albedo.R`, `.G`, `.B`).
    Albedo,
    /// First-hit shading normal in world space (`normal.X`, `.Y`, `.Z`).
    Normal,
    /// Distance along the camera ray to the first hit (`depth.Z`).
    Depth,
}

impl AuxPass {
    /// Every pass, in the order `--aov` names them.
    pub const ALL: [AuxPass; 3] = [AuxPass::Albedo, AuxPass::Normal, AuxPass::Depth];

    /// The pass's name on the command line and in the file (`albedo`, `normal`,
    /// `depth`).
    pub fn name(self) -> &'static str {
        match self {
            AuxPass::Albedo => "albedo",
            AuxPass::Normal => "normal",
            AuxPass::Depth => "depth",
        }
    }

    /// The pass named `name`, if there is one.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|pass| pass.name() == name)
    }
}

/// Writes `image` and the `passes` asked for from `aux` to the OpenEXR file `path`,
/// atomically. The buffers must all hold the image's pixels.
pub fn write_exr_with_passes(
    path: &Path,
    image: &LinearImage,
    aux: &GuidePasses,
    passes: &[AuxPass],
) -> Result<(), OutputError> {
    let bad = |message: String| OutputError::BadImage {
        path: path.to_path_buf(),
        message,
    };
    let (width, height) = (image.width as usize, image.height as usize);
    let pixels = width * height;
    if pixels == 0
        || image.pixels.len() != pixels
        || (aux.width, aux.height) != (image.width, image.height)
        || aux.albedo.len() != pixels
        || aux.normal.len() != pixels
        || aux.depth.len() != pixels
    {
        return Err(bad(format!(
            "the image ({}x{}) and its passes ({}x{}) differ in size",
            image.width, image.height, aux.width, aux.height
        )));
    }
    let channel = |name: &str, samples: Vec<f32>| {
        AnyChannel::new(Text::from(name), FlatSamples::F32(samples))
    };
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (name, c) in [("R", 0), ("G", 1), ("B", 2), ("A", 3)] {
        channels.push(channel(name, image.pixels.iter().map(|p| p[c]).collect()));
    }
    for pass in passes {
        match pass {
            AuxPass::Albedo => {
                for (suffix, c) in [("R", 0), ("G", 1), ("B", 2)] {
                    let samples = aux.albedo.iter().map(|a| a[c]).collect();
                    channels.push(channel(&format!("albedo.{suffix}"), samples));
                }
            }
            AuxPass::Normal => {
                for (suffix, c) in [("X", 0), ("Y", 1), ("Z", 2)] {
                    let samples = aux.normal.iter().map(|n| n[c]).collect();
                    channels.push(channel(&format!("normal.{suffix}"), samples));
                }
            }
            AuxPass::Depth => channels.push(channel("depth.Z", aux.depth.clone())),
        }
    }
    let layer = Layer::new(
        Vec2(width, height),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels),
    );
    let file = Image::new(
        ImageAttributes::new(IntegerBounds::from_dimensions(Vec2(width, height))),
        layer,
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    {
        use exr::prelude::WritableImage;
        file.write()
            .to_buffered(&mut bytes)
            .map_err(|e| OutputError::EncodeExr {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
    }
    write_bytes(path, &bytes.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_are_named_channels_that_read_back() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("aov.exr");
        let mut image = LinearImage::new(3, 2);
        for (i, p) in image.pixels.iter_mut().enumerate() {
            *p = [i as f32, 0.5, 0.25, 1.0];
        }
        let aux = GuidePasses {
            width: 3,
            height: 2,
            albedo: (0..6).map(|i| [0.1 * i as f32, 0.2, 0.3]).collect(),
            normal: vec![[0.0, 1.0, 0.0]; 6],
            depth: (0..6).map(|i| i as f32 + 0.5).collect(),
        };
        write_exr_with_passes(&path, &image, &aux, &AuxPass::ALL).expect("written");
        let read = exr::prelude::read_all_flat_layers_from_file(&path).expect("reads");
        let layer = &read.layer_data[0];
        let names: Vec<String> = layer
            .channel_data
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        assert_eq!(
            names,
            [
                "A", "B", "G", "R", "albedo.B", "albedo.G", "albedo.R", "depth.Z", "normal.X",
                "normal.Y", "normal.Z"
            ]
        );
        let samples = |name: &str| -> Vec<f32> {
            let channel = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name == *name)
                .expect("channel");
            match &channel.sample_data {
                FlatSamples::F32(v) => v.clone(),
                other => panic!("{name}: {other:?}"),
            }
        };
        assert_eq!(samples("R"), [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(samples("depth.Z"), aux.depth);
        assert_eq!(samples("albedo.R")[5], 0.5);
        assert_eq!(samples("normal.Y"), [1.0; 6]);
    }

    #[test]
    fn pass_names_round_trip() {
        for pass in AuxPass::ALL {
            assert_eq!(AuxPass::from_name(pass.name()), Some(pass));
        }
        assert_eq!(AuxPass::from_name("speed"), None);
    }
}
