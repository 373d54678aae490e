//! The environment map on the device: the shared [`EnvironmentLight`] (the map, its
//! rotation and scale, and its piecewise-constant sampling tables) as one storage
//! buffer (binding 20) that `shaders/environment.wgsl` reads: an
//! [`GpuEnvironmentHeader`] (`EnvironmentHeader` in `shaders/path_types.wgsl`, checked
//! by `tests/integration/layout.rs`) followed by `f32` data in this order, for a map of `w × h`
//! texels:
//!
//! 1. the texels' red, green and blue, row by row from the top (`3 w h` values);
//! 2. the sampling function `f(x, y)` of every texel (`w h`);
//! 3. each row's conditional cumulative values (`h (w + 1)`);
//! 4. the marginal cumulative values over the rows (`h + 1`).
//!
//! A scene without a map uploads a header of width 0 (and padding: the buffer is at
//! least [`MIN_ENVIRONMENT_BYTES`] long, a multiple of 16): the shader then sees the
//! constant background.

use bytemuck::{Pod, Zeroable};

use crate::accel::EnvironmentLight;

/// The least size of the environment buffer: WGSL's `EnvironmentBuffer` (the header
/// and at least one `f32`, rounded up to its 16-byte alignment).
pub const MIN_ENVIRONMENT_BYTES: usize = 64;

/// The header of the environment buffer (`EnvironmentHeader` in WGSL).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuEnvironmentHeader {
    /// The radiance scale per channel.
    pub scale: [f32; 3],
    /// Width in texels; 0 when the scene has no map.
    pub width: u32,
    /// `(cos α, sin α)` of the rotation α about +y.
    pub rotation: [f32; 2],
    /// Height in texels.
    pub height: u32,
    /// The probability that next-event estimation picks the environment.
    pub selection: f32,
    /// `∫ f` over the unit square (the marginal distribution's integral); 0 for a
    /// black map.
    pub integral: f32,
    /// Padding to 16-byte alignment.
    pub _pad: [u32; 3],
}

/// The environment buffer's bytes for `environment` (a header of width 0 without),
/// zero-padded to a multiple of 16 bytes and at least [`MIN_ENVIRONMENT_BYTES`].
pub fn environment_buffer(environment: Option<&EnvironmentLight>) -> Vec<u8> {
    let mut bytes = environment_bytes(environment);
    while bytes.len() < MIN_ENVIRONMENT_BYTES || !bytes.len().is_multiple_of(16) {
        bytes.push(0);
    }
    bytes
}

fn environment_bytes(environment: Option<&EnvironmentLight>) -> Vec<u8> {
    let Some(light) = environment else {
        return bytemuck::bytes_of(&GpuEnvironmentHeader::zeroed()).to_vec();
    };
    let map = &light.map;
    let (w, h) = (map.image.width, map.image.height);
    let rotation = map.rotation_cos_sin();
    let header = GpuEnvironmentHeader {
        scale: map.scale.as_vec3().to_array(),
        width: w,
        rotation: [rotation.x as f32, rotation.y as f32],
        height: h,
        selection: light.selection as f32,
        integral: light.marginal.integral as f32,
        _pad: [0; 3],
    };
    let (w, h) = (w as usize, h as usize);
    let mut data: Vec<f32> = Vec::with_capacity(5 * w * h + 2 * h + 1);
    data.extend(map.image.texels.iter().flat_map(|t| [t[0], t[1], t[2]]));
    for row in &light.conditional {
        data.extend(row.func.iter().map(|&f| f as f32));
    }
    for row in &light.conditional {
        data.extend(row.cdf.iter().map(|&c| c as f32));
    }
    data.extend(light.marginal.cdf.iter().map(|&c| c as f32));
    let mut bytes = bytemuck::bytes_of(&header).to_vec();
    bytes.extend_from_slice(bytemuck::cast_slice(&data));
    bytes
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::DVec3;

    use super::*;
    use crate::scene::{EnvironmentMap, Image};

    #[test]
    fn the_buffer_holds_the_header_then_texels_functions_and_both_cdfs() {
        let texels = (0..6).map(|i| [i as f32, 0.0, 1.0, 1.0]).collect();
        let map = EnvironmentMap {
            image: Image {
                path: "m.exr".into(),
                width: 3,
                height: 2,
                texels,
            },
            rotation_degrees: 90.0,
            scale: DVec3::splat(2.0),
        };
        let light = EnvironmentLight::new(Arc::new(map), true);
        let bytes = environment_buffer(Some(&light));
        let header: GpuEnvironmentHeader = bytemuck::pod_read_unaligned(&bytes[..48]);
        assert_eq!((header.width, header.height), (3, 2));
        assert_eq!(header.selection, 0.5);
        assert!(header.rotation[0].abs() < 1e-7 && header.rotation[1] == 1.0);
        let data: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes[48..]);
        // 35 values and one of padding.
        assert_eq!(data.len(), 18 + 6 + 2 * 4 + 3 + 1);
        assert_eq!(data[3], 1.0);
        // The last value of each cumulative table is 1.
        assert_eq!(data[24 + 3], 1.0);
        assert_eq!(data[24 + 7], 1.0);
        assert_eq!(data[34], 1.0);
        let none = environment_buffer(None);
        assert_eq!(none.len(), MIN_ENVIRONMENT_BYTES);
        assert!(none.iter().all(|&b| b == 0));
    }
}
