//! [`GpuScene`]: a scene uploaded to one device, with its trace pipelines built, and
//! its camera kept on the host so that a camera move uploads nothing but the next
//! trace pass's constants.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use wgpu::util::DeviceExt;

use super::ShaderFeatures;
use super::layout::{DisplayUniforms, FLAG_ORTHOGRAPHIC, FLAG_TEXTURE_FILTERING, FrameUniforms};
use super::pipelines::TracePipelines;
use super::scene_buffers::DeviceScene;
use crate::accel::BvhStats;
use crate::camera::{CameraFrame, PixelCone};
use crate::scene::{Camera, DielectricSphere, MediumStack, media_around};

/// Identities of uploaded scenes, so that a film knows which scene its bind group
/// was built for.
static NEXT_SCENE_ID: AtomicU64 = AtomicU64::new(1);

/// A scene uploaded to one device by [`super::Renderer::upload`]: its storage
/// buffers and images, the trace pipelines specialised to its features (built at
/// upload, never while encoding), and its camera.
///
/// The camera is not in any GPU buffer of the scene: [`super::Renderer::set_camera`]
/// changes it on the host, and the next trace pass of each film writes it with the
/// pass's other constants (one [`FrameUniforms`] record, 208 bytes).
#[derive(Debug)]
pub struct GpuScene {
    pub(crate) id: u64,
    pub(crate) prepared: DeviceScene,
    pub(crate) pipelines: TracePipelines,
    /// The display pass's constants (the scene's sRGB rule), bound by
    /// [`super::Renderer::encode_display`].
    pub(crate) display_uniforms: wgpu::Buffer,
    pub(crate) camera: Camera,
    /// Increased by every camera change: films accumulating an older camera restart.
    pub(crate) camera_version: u64,
    dielectric_spheres: Vec<DielectricSphere>,
    compile_time: Duration,
    /// Each kernel's first dispatch when the upload built them ([`Self::kernel_compiles`]).
    pub(crate) kernel_compiles: Vec<super::wavefront::KernelCompile>,
}

impl GpuScene {
    pub(crate) fn new(
        device: &wgpu::Device,
        prepared: DeviceScene,
        pipelines: TracePipelines,
        compile_time: Duration,
        camera: Camera,
        dielectric_spheres: Vec<DielectricSphere>,
    ) -> Self {
        let uniforms = DisplayUniforms {
            encode_srgb: u32::from(prepared.display_encodes_srgb()),
            _pad: [0; 3],
        };
        let display_uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("gpu-render display uniforms"),
            contents: bytemuck::bytes_of(&uniforms),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        Self {
            id: NEXT_SCENE_ID.fetch_add(1, Ordering::Relaxed),
            prepared,
            pipelines,
            display_uniforms,
            camera,
            camera_version: 0,
            dielectric_spheres,
            compile_time,
            kernel_compiles: Vec::new(),
        }
    }

    /// The scene's image width in pixels (its render settings'; a film may have
    /// another size).
    pub fn width(&self) -> u32 {
        self.prepared.width()
    }

    /// The scene's image height in pixels.
    pub fn height(&self) -> u32 {
        self.prepared.height()
    }

    /// The scene's samples per pixel: the size of the stratified sample pattern
    /// (`crate::camera::SamplePattern`). A film that has accumulated this many samples
    /// holds exactly the image of a one-shot render; more samples continue the
    /// sequence.
    pub fn samples_per_pixel(&self) -> u32 {
        self.prepared.samples_per_pixel()
    }

    /// The camera the next trace pass uses.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Whether the scene's display values are sRGB-encoded linear radiance (`true`) or
    /// already display values (naive gamma mode). [`super::Renderer::encode_display`]
    /// and [`super::Renderer::draw`] apply this rule themselves.
    pub fn display_encodes_srgb(&self) -> bool {
        self.prepared.display_encodes_srgb()
    }

    /// Bytes of the scene's storage buffers on the device (primitives, BVH,
    /// materials, lights; not the images): what a full re-upload writes besides the
    /// images.
    pub fn scene_bytes(&self) -> u64 {
        self.prepared.scene_bytes()
    }

    /// Bytes of the scene's image array on the device (albedo textures and BRDF
    /// maps, `Rgba32Float`, at least one 1×1 layer).
    pub fn image_bytes(&self) -> u64 {
        self.prepared.image_bytes()
    }

    /// Capacity of each path's bounce stack (a film made for this scene holds it).
    pub fn stack_size(&self) -> u32 {
        self.prepared.stack_size()
    }

    /// The shader features of the scene's trace pipelines (what its module contains).
    pub fn features(&self) -> ShaderFeatures {
        self.prepared.features()
    }

    /// How the BVH the GPU walks was built: the scene's, or with the hardware
    /// traversal the analytic shapes' alone (the driver builds the triangles'
    /// structures, whose figures wgpu does not give).
    pub fn bvh_stats(&self) -> &BvhStats {
        self.prepared.bvh_stats()
    }

    /// How long [`super::Renderer::upload`] spent building the scene's trace
    /// pipelines and running each once over no work (drivers compile at pipeline
    /// creation or, as lavapipe does, at the first dispatch): the kernel compile.
    /// Zero when the renderer had them cached from an earlier scene with the same
    /// features.
    pub fn compile_time(&self) -> Duration {
        self.compile_time
    }

    /// Each kernel the upload built and how long its first dispatch took (the compile,
    /// on drivers that compile there, as lavapipe does); empty when the renderer had
    /// the kernels from an earlier scene.
    pub fn kernel_compiles(&self) -> &[super::wavefront::KernelCompile] {
        &self.kernel_compiles
    }

    /// The trace constants of the whole image at upload, before any camera move (the
    /// scheduler sets region, samples, slots and budget per trace).
    pub fn frame_uniforms(&self) -> &FrameUniforms {
        self.prepared.frame_uniforms()
    }

    /// The trace constants of one pass over a `width × height` film: the scene's
    /// settings, this camera (its basis, field of view and the dielectrics around
    /// it), the film's size, and the sample pattern of the scene's samples per pixel.
    /// The scheduler fills in the sample range, slots and budget.
    pub(crate) fn frame_for(&self, width: u32, height: u32) -> FrameUniforms {
        let camera = CameraFrame::new(&self.camera, width, height);
        let medium = MediumStack::from_outermost_first(&media_around(
            self.camera.eye,
            &self.dielectric_spheres,
        ));
        let v = |d: glam::DVec3| d.as_vec3().to_array();
        let (tan_half_fov_y, projection_flag) = super::upload::projection_uniforms(&camera);
        let flags = (self.prepared.frame.flags & !FLAG_ORTHOGRAPHIC) | projection_flag;
        // This camera's ray cone where the scene filters its textures.
        let cone = if flags & FLAG_TEXTURE_FILTERING != 0 {
            camera.pixel_cone(height, self.prepared.frame.samples_per_pixel)
        } else {
            PixelCone::default()
        };
        FrameUniforms {
            eye: v(camera.eye),
            tan_half_fov_y: tan_half_fov_y as f32,
            flags,
            forward: v(camera.forward),
            aspect: camera.aspect as f32,
            right: v(camera.right),
            width,
            up: v(camera.up),
            height,
            camera_medium_iors: medium.iors.map(|ior| ior as f32),
            camera_medium_depth: medium.depth,
            region_x: 0,
            region_y: 0,
            region_width: width,
            region_height: height,
            target_x: 0,
            target_y: 0,
            lens_radius: camera.lens_radius as f32,
            focus_distance: camera.focus_distance as f32,
            cone_width: cone.width as f32,
            cone_spread: cone.spread as f32,
            ..self.prepared.frame
        }
    }
}
