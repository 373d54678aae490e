//! What a tile records about the render it belongs to, so that tiles of different
//! renders are never merged: a hash of the scene and one of the render settings.
//!
//! The scene hash covers everything a pixel depends on apart from the render
//! settings: the camera (of the frame, for an animation), the environment, the
//! materials, the lights, the shapes, the meshes and the texels of every image (the
//! environment map's included), but not the paths
//! the files were read from (a farm mounts them in other places). The settings hash
//! covers the image size, samples per pixel, depth, stack size, lighting space and
//! ray-weight cutoff. Settings that only change how the work is scheduled (the GPU's
//! iteration budget, the slot count) are in neither: the image does not depend on
//! them.
//!
//! Both are 64-bit FNV-1a hashes (Fowler, Noll and Vo), stable across runs, machines
//! and builds, of the values' exact `Debug` text (Rust prints every `f64` so that it
//! reads back to the same bits) and of the texels' bytes, prefixed by
//! [`FINGERPRINT_VERSION`]. They detect mistakes (a tile of another scene, frame or
//! sample count), not forgery.

use std::fmt::{self, Write as _};

use crate::scene::{RenderSettings, Scene};

/// Changes whenever what the hashes cover changes, so that tiles hashed differently
/// never agree.
pub const FINGERPRINT_VERSION: u32 = 3;

/// The hashes a tile records of its render.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Fingerprint {
    /// The scene as rendered, without its render settings.
    pub scene: u64,
    /// The render settings that affect pixels.
    pub settings: u64,
}

impl Fingerprint {
    /// The fingerprint of rendering `scene` (with its render settings, as overridden
    /// on the command line, and its camera at the frame rendered).
    pub fn of(scene: &Scene) -> Self {
        let mut hash = Fnv1a::new("scene");
        // `Debug` of the parts by name, so the image paths stay out.
        let parts: [(&str, &dyn fmt::Debug); 7] = [
            ("camera", &scene.camera),
            ("environment", &scene.environment),
            ("materials", &scene.materials),
            ("material_names", &scene.material_names),
            ("lights", &scene.lights),
            ("shapes", &scene.shapes),
            ("meshes", &scene.meshes),
        ];
        for (name, value) in parts {
            hash.debug(name, value);
        }
        for image in &scene.images {
            hash.debug("image", &(image.width, image.height));
            hash.bytes(bytemuck::cast_slice(&image.texels));
        }
        // The environment's `Debug` has the map's size, rotation and scale; its texels
        // are hashed here.
        if let Some(map) = &scene.environment.map {
            hash.bytes(bytemuck::cast_slice(&map.image.texels));
        }
        Self {
            scene: hash.finish(),
            settings: settings_hash(&scene.render),
        }
    }
}

/// The hash of the render settings that affect pixels.
pub fn settings_hash(settings: &RenderSettings) -> u64 {
    let mut hash = Fnv1a::new("settings");
    hash.debug("render", settings);
    hash.finish()
}

/// The settings in words, as a tile records them for messages:
/// `640x480, 4 spp, max depth 5, stack 6, linear lighting, min ray weight 0`.
pub fn describe_settings(settings: &RenderSettings) -> String {
    format!(
        "{}x{}, {} spp, max depth {}, stack {}, {} lighting, min ray weight {}",
        settings.width,
        settings.height,
        settings.samples_per_pixel,
        settings.max_depth,
        settings.stack_size,
        match settings.lighting_space {
            crate::scene::LightingSpace::Linear => "linear",
            crate::scene::LightingSpace::NaiveGamma => "naive gamma",
        },
        settings.min_ray_weight
    )
}

/// 64-bit FNV-1a, fed bytes and `Debug` text (streamed, never held whole).
struct Fnv1a(u64);

impl Fnv1a {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    fn new(domain: &str) -> Self {
        let mut hash = Self(Self::OFFSET);
        hash.debug(domain, &FINGERPRINT_VERSION);
        hash
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.0 = (self.0 ^ u64::from(byte)).wrapping_mul(Self::PRIME);
        }
    }

    /// `name=value;` with the value's `Debug` text.
    fn debug(&mut self, name: &str, value: &dyn fmt::Debug) {
        // Writing into the hash cannot fail.
        let _ = write!(self, "{name}={value:?};");
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

impl fmt::Write for Fnv1a {
    fn write_str(&mut self, text: &str) -> fmt::Result {
        self.bytes(text.as_bytes());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::parse_scene;

    fn scene(extra: &str) -> Scene {
        let text = format!(
            "[render]\nwidth = 8\nheight = 6\n{extra}\n[camera]\neye = [0, 0, 3]\nlook_at = [0, 0, 0]\n\
             [materials.m]\ntype = \"lambert\"\nalbedo = 0.5\n[[objects]]\ntype = \"sphere\"\n\
             center = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n"
        );
        parse_scene(&text, std::path::Path::new("<test>")).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn the_hash_of_a_known_text_is_fnv1a() {
        // The published FNV-1a 64 test vector for "a".
        let mut hash = Fnv1a(Fnv1a::OFFSET);
        hash.bytes(b"a");
        assert_eq!(hash.finish(), 0xaf63_dc4c_8601_ec8c);
    }

    #[test]
    fn equal_scenes_agree_and_any_change_shows() {
        let base = Fingerprint::of(&scene(""));
        assert_eq!(base, Fingerprint::of(&scene("")));
        let more_samples = Fingerprint::of(&scene("samples_per_pixel = 2"));
        assert_eq!(more_samples.scene, base.scene);
        assert_ne!(more_samples.settings, base.settings);
        let mut moved = scene("");
        moved.camera.eye.x += 1e-12;
        let moved = Fingerprint::of(&moved);
        assert_ne!(moved.scene, base.scene);
        assert_eq!(moved.settings, base.settings);
    }

    #[test]
    fn image_paths_do_not_count_but_texels_do() {
        let mut a = scene("");
        a.images.push(crate::scene::Image {
            path: "/mnt/a/wood.png".into(),
            width: 1,
            height: 1,
            texels: vec![[0.5; 4]],
        });
        let mut b = a.clone();
        b.images[0].path = "/srv/b/wood.png".into();
        assert_eq!(Fingerprint::of(&a), Fingerprint::of(&b));
        b.images[0].texels[0][1] = 0.25;
        assert_ne!(Fingerprint::of(&a).scene, Fingerprint::of(&b).scene);
    }

    #[test]
    fn an_environment_maps_texels_rotation_and_scale_count_but_not_its_path() {
        let map = crate::scene::EnvironmentMap {
            image: crate::scene::Image {
                path: "/mnt/a/sky.hdr".into(),
                width: 2,
                height: 1,
                texels: vec![[1.0; 4]; 2],
            },
            rotation_degrees: 10.0,
            scale: glam::DVec3::ONE,
        };
        let mut a = scene("");
        a.environment.map = Some(std::sync::Arc::new(map.clone()));
        let with = |change: fn(&mut crate::scene::EnvironmentMap)| {
            let mut changed = map.clone();
            change(&mut changed);
            let mut b = a.clone();
            b.environment.map = Some(std::sync::Arc::new(changed));
            Fingerprint::of(&b)
        };
        assert_eq!(
            with(|m| m.image.path = "/srv/b/sky.hdr".into()),
            Fingerprint::of(&a)
        );
        assert_ne!(with(|m| m.image.texels[1][2] = 0.5), Fingerprint::of(&a));
        assert_ne!(with(|m| m.rotation_degrees = 11.0), Fingerprint::of(&a));
        assert_ne!(with(|m| m.scale.y = 2.0), Fingerprint::of(&a));
        assert_ne!(Fingerprint::of(&a), Fingerprint::of(&scene("")));
    }

    #[test]
    fn settings_read_as_words() {
        let settings = scene("samples_per_pixel = 4").render;
        assert_eq!(
            describe_settings(&settings),
            "8x6, 4 spp, max depth 5, stack 6, linear lighting, min ray weight 0"
        );
    }
}
