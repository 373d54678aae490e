//! The wavefront schedule: path slots in storage buffers, and the host loop that
//! dispatches the two trace kernels in turns until every pixel of a region is done.
//!
//! A trace of one region runs in submissions of `rounds` rounds, each round one
//! dispatch of `shade_paths` and one of `trace_rays` over every slot. After each
//! submission the host reads the shared counters (pixels finished, rays, error bits)
//! and, where the device has timestamp queries, the GPU time of the submission; the
//! number of rounds per submission adapts so that each takes about
//! [`TARGET_SUBMISSION`]. Every buffer is created once per trace, whatever the number
//! of samples, rounds or submissions.

use std::time::{Duration, Instant};

use super::RenderError;
use super::error::TraceFailure;
use super::layout::{
    ERROR_LOOP_CUT, ERROR_TRAVERSAL_STACK, FrameUniforms, GpuCounters, GpuPathState, GpuStackEntry,
    GpuTraceRay, static_pixels_for,
};
use super::pipelines::LINEAR_FORMAT;
use super::pipelines::{TracePipelines, binding};
use super::readback::{Caught, capture, create_texture, map_read, read_buffer, submit_and_wait};
use super::scene_buffers::DeviceScene;
use super::shaders::SLOT_WORKGROUP_SIZE;
use crate::accel::MAX_TRAVERSAL_STACK;
use crate::denoise::GuidePasses;
use crate::noise::NoiseEstimate;

/// llvmpipe's (and so lavapipe's) limit on the loop iterations of one shader
/// invocation: `LP_MAX_TGSI_LOOP_ITERATIONS` in Mesa's gallivm. Past it every loop of
/// the invocation ends silently.
pub const LLVMPIPE_LOOP_LIMIT: u32 = 65_535;

/// Lanes of one SIMD vector of llvmpipe: the vector width its name states
/// ("llvmpipe (LLVM 15.0.6, 256 bits)": 8 lanes of 32 bits), else 16 (AVX-512's).
fn llvmpipe_lanes(adapter: &wgpu::AdapterInfo) -> u32 {
    let name = &adapter.name;
    let bits = name.find(" bits").and_then(|end| {
        let start = name[..end].rfind(|c: char| !c.is_ascii_digit())? + 1;
        name[start..end].parse::<u32>().ok()
    });
    bits.map_or(16, |bits| (bits / 32).max(1))
}

/// The Mesa version an adapter's driver reports in its driver info, for example
/// `(25, 0)` from "Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)".
fn mesa_version(adapter: &wgpu::AdapterInfo) -> Option<(u32, u32)> {
    let rest = &adapter.driver_info[adapter.driver_info.find("Mesa ")? + 5..];
    let mut numbers = rest.split(|c: char| !c.is_ascii_digit());
    let major = numbers.next()?.parse().ok()?;
    let minor = numbers.next()?.parse().ok()?;
    Some((major, minor))
}

/// The loop limit `adapter`'s driver imposes on one shader invocation, where one is
/// known: llvmpipe before Mesa 25 ends every loop of an invocation once its vector of
/// lanes has run [`LLVMPIPE_LOOP_LIMIT`] iterations in all (measured on Mesa 22.3.6;
/// Mesa 25.0.7 counted a loop of 10,000,000 iterations to the end:
/// `tools/src/bin/loop_probe.rs`). An llvmpipe whose version cannot be read is taken to have
/// the limit.
pub fn driver_loop_limit(adapter: &wgpu::AdapterInfo) -> Option<u32> {
    let llvmpipe = |s: &str| s.to_lowercase().contains("llvmpipe");
    let is_llvmpipe =
        llvmpipe(&adapter.name) || llvmpipe(&adapter.driver) || llvmpipe(&adapter.driver_info);
    let fixed = mesa_version(adapter).is_some_and(|(major, _)| major >= 25);
    (is_llvmpipe && !fixed).then_some(LLVMPIPE_LOOP_LIMIT)
}

/// The iteration budget of one invocation per dispatch on `adapter`.
///
/// Where the driver limits loops ([`driver_loop_limit`]), a vector of lanes shares
/// the limit and iterates only while one of its lanes does, so its count is at most
/// the sum of its lanes': each lane gets the limit divided by the lanes per vector,
/// less 2048 for what a lane may run past its budget (the planes of a traversal's
/// start, at most [`crate::accel::MAX_PLANES`], and its one guaranteed step).
/// Elsewhere 2^20, which keeps one dispatch short.
pub fn iteration_budget_for(adapter: &wgpu::AdapterInfo) -> u32 {
    match driver_loop_limit(adapter) {
        Some(limit) => limit / llvmpipe_lanes(adapter) - 2048,
        None => 1 << 20,
    }
}

/// Bytes of one slot's traversal stack: [`MAX_TRAVERSAL_STACK`] entries of a child
/// word and an entry distance (`traversal_stack` in `shaders/bindings.wgsl`).
pub const TRAVERSAL_STACK_BYTES_PER_SLOT: u64 = MAX_TRAVERSAL_STACK as u64 * 2 * 4;

/// The number of path slots a trace uses on `adapter` when the caller does not choose:
/// on CPU devices [`CPU_SLOTS_PER_THREAD`] for each of the host's threads (llvmpipe
/// runs one per core; counted as at least two, the whole at most 131,072), 131,072
/// elsewhere.
pub fn default_slot_count(adapter: &wgpu::AdapterInfo) -> u32 {
    if adapter.device_type == wgpu::DeviceType::Cpu {
        cpu_slot_count(std::thread::available_parallelism().map_or(1, usize::from))
    } else {
        1 << 17
    }
}

/// Path slots per CPU thread on CPU devices: eight workgroups of 256 for each thread
/// to balance, and about 2 MiB of slot state (path, trace and traversal stack, about
/// 1 KiB a slot) per core, where the 16,384 slots used before gave each of two cores
/// 8 MiB. On the 2-core machine the bunny (`scenes/bench/bunny.toml`, 32 spp) traced
/// 8% faster with 4,096 slots than with 16,384, the million-triangle terrain 1% and
/// `glass.toml` 3%; the showcase took the same time (BENCHMARKS.md, "Path slots on
/// CPU devices").
pub const CPU_SLOTS_PER_THREAD: u32 = 2048;

/// The CPU-device slot count for `threads` host threads ([`default_slot_count`]).
fn cpu_slot_count(threads: usize) -> u32 {
    let threads = u32::try_from(threads).unwrap_or(u32::MAX).max(2);
    threads.saturating_mul(CPU_SLOTS_PER_THREAD).min(1 << 17)
}

/// How the trace kernels are dispatched (`docs/model.md`, "Bounded work"). Both run the
/// same functions in the same order for every slot, so the image does not depend on
/// the choice; only the speed does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Schedule {
    /// Rounds of two kernels: `shade_paths` (one shading step per slot), then
    /// `trace_rays` (one traversal per slot); the path state goes through memory
    /// between them. Small, coherent kernels: the layout GPUs are built for (Laine,
    /// Karras and Aila 2013).
    Wavefront,
    /// One kernel, `trace_paths`, in which each slot alternates traversals and shading
    /// steps until its budget is spent, its state in registers between rays. Faster on
    /// llvmpipe, where every dispatch and every load and store of a lane's state costs
    /// more than the arithmetic (`BENCHMARKS.md`).
    Fused,
}

/// The schedule a trace uses on `adapter` when the caller does not choose: fused on
/// CPU devices (measured faster on lavapipe), the wavefront elsewhere.
pub fn default_schedule(adapter: &wgpu::AdapterInfo) -> Schedule {
    if adapter.device_type == wgpu::DeviceType::Cpu {
        Schedule::Fused
    } else {
        Schedule::Wavefront
    }
}

/// Bytes of a pixel's sample sum and luminance m2 in the accumulation buffer.
pub(crate) const SUM_BYTES_PER_PIXEL: u64 = 16;
/// Bytes of a pixel's sums of the auxiliary passes after the sample sums (albedo and
/// depth, normal and the samples counted: `shaders/aov.wgsl`).
pub(crate) const AOV_BYTES_PER_PIXEL: u64 = 32;

/// How long one submission of rounds should take.
pub const TARGET_SUBMISSION: Duration = Duration::from_millis(100);

/// Most rounds in one submission.
const MAX_ROUNDS: u32 = 4096;

/// Bytes of the readback buffer: the counters at 0, the two timestamps at 256.
const READBACK_SIZE: u64 = 256 + 16;

/// The buffers of a trace's path slots.
#[derive(Debug)]
pub(crate) struct SlotBuffers {
    pub uniforms: wgpu::Buffer,
    pub paths: wgpu::Buffer,
    pub traces: wgpu::Buffer,
    ray_stack: wgpu::Buffer,
    traversal_stack: wgpu::Buffer,
    pub counters: wgpu::Buffer,
    pub accumulation: wgpu::Buffer,
    readback: wgpu::Buffer,
    timestamps: Option<(wgpu::QuerySet, wgpu::Buffer)>,
}

impl SlotBuffers {
    /// The slot count for a region of `pixels` pixels: `requested` (or the adapter's
    /// default), at most one slot per pixel, and few enough that the largest slot
    /// buffer fits one storage binding.
    pub fn slot_count(
        device: &wgpu::Device,
        requested: Option<u32>,
        pixels: u64,
        stack_size: u32,
    ) -> u32 {
        let limits = device.limits();
        let binding = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size);
        let largest_per_slot = (u64::from(stack_size.max(1)) * size_of::<GpuStackEntry>() as u64)
            .max(size_of::<GpuPathState>() as u64)
            .max(TRAVERSAL_STACK_BYTES_PER_SLOT);
        let fits = binding / largest_per_slot;
        let workgroups =
            u64::from(limits.max_compute_workgroups_per_dimension) * u64::from(SLOT_WORKGROUP_SIZE);
        let wanted =
            u64::from(requested.unwrap_or_else(|| default_slot_count(&device.adapter_info())));
        wanted.min(pixels).min(fits).min(workgroups).max(1) as u32
    }

    /// Creates the buffers for `slot_count` slots with bounce stacks of `stack_size`,
    /// and an accumulation buffer of one sum per pixel for `accumulation_pixels`
    /// pixels (0 for whole renders, which keep no sums), with `aov` followed by each
    /// pixel's sums of the auxiliary passes ([`AOV_BYTES_PER_PIXEL`]).
    pub fn new(
        device: &wgpu::Device,
        slot_count: u32,
        stack_size: u32,
        accumulation_pixels: u64,
        aov: bool,
    ) -> Result<Self, RenderError> {
        let accumulation_bytes =
            accumulation_pixels * (SUM_BYTES_PER_PIXEL + u64::from(aov) * AOV_BYTES_PER_PIXEL);
        let storage = |label: &str, bytes: u64, extra: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes.max(16),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
                mapped_at_creation: false,
            })
        };
        let slots = u64::from(slot_count);
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        capture(device, "path slot buffers", Caught::Resource, || Self {
            uniforms: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render trace uniforms"),
                size: size_of::<FrameUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            paths: storage(
                "gpu-render path states",
                slots * size_of::<GpuPathState>() as u64,
                wgpu::BufferUsages::empty(),
            ),
            traces: storage(
                "gpu-render traces",
                slots * size_of::<GpuTraceRay>() as u64,
                wgpu::BufferUsages::empty(),
            ),
            ray_stack: storage(
                "gpu-render bounce stacks",
                slots * u64::from(stack_size) * size_of::<GpuStackEntry>() as u64,
                wgpu::BufferUsages::empty(),
            ),
            traversal_stack: storage(
                "gpu-render traversal stacks",
                slots * TRAVERSAL_STACK_BYTES_PER_SLOT,
                wgpu::BufferUsages::empty(),
            ),
            counters: storage(
                "gpu-render counters",
                size_of::<GpuCounters>() as u64,
                wgpu::BufferUsages::COPY_SRC,
            ),
            // One vec4 sum per pixel (progressive rendering), and the passes' sums;
            // whole renders keep none and get the 16-byte minimum.
            accumulation: storage(
                "gpu-render accumulation",
                accumulation_bytes,
                wgpu::BufferUsages::COPY_SRC,
            ),
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("gpu-render counter readback"),
                size: READBACK_SIZE,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            }),
            timestamps: timestamps.then(|| {
                (
                    device.create_query_set(&wgpu::QuerySetDescriptor {
                        label: Some("gpu-render trace timestamps"),
                        ty: wgpu::QueryType::Timestamp,
                        count: 2,
                    }),
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("gpu-render timestamp resolve"),
                        size: 16,
                        usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                        mapped_at_creation: false,
                    }),
                )
            }),
        })
    }

    /// Reads the accumulation of `width × height` region pixels after `samples`
    /// samples back as their noise estimate (blocking).
    pub fn read_noise(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (width, height): (u32, u32),
        samples: u32,
        timeout: Option<Duration>,
    ) -> Result<NoiseEstimate, RenderError> {
        let pixels = u64::from(width) * u64::from(height);
        let bytes = read_buffer(device, queue, &self.accumulation, pixels * 16, timeout)?;
        let float = |b: &[u8]| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        Ok(NoiseEstimate::from_sums(
            width,
            height,
            samples,
            bytes.chunks_exact(16).map(|s| {
                (
                    glam::DVec3::new(float(&s[0..4]), float(&s[4..8]), float(&s[8..12])),
                    float(&s[12..16]),
                )
            }),
        ))
    }

    /// Reads the auxiliary passes of `width × height` region pixels after `samples`
    /// samples back (blocking): their sums, kept after the sample sums by a trace with
    /// [`super::layout::FLAG_AOV`], divided by the sample count.
    pub fn read_aov(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (width, height): (u32, u32),
        samples: u32,
        timeout: Option<Duration>,
    ) -> Result<GuidePasses, RenderError> {
        let pixels = u64::from(width) * u64::from(height);
        let bytes = read_buffer(
            device,
            queue,
            &self.accumulation,
            pixels * (SUM_BYTES_PER_PIXEL + AOV_BYTES_PER_PIXEL),
            timeout,
        )?;
        let sums: Vec<[f32; 8]> =
            bytemuck::pod_collect_to_vec(&bytes[(pixels * SUM_BYTES_PER_PIXEL) as usize..]);
        let scale = 1.0 / samples.max(1) as f32;
        Ok(GuidePasses {
            width,
            height,
            albedo: sums
                .iter()
                .map(|s| [s[0] * scale, s[1] * scale, s[2] * scale])
                .collect(),
            normal: sums
                .iter()
                .map(|s| [s[4] * scale, s[5] * scale, s[6] * scale])
                .collect(),
            depth: sums.iter().map(|s| s[3] * scale).collect(),
        })
    }

    /// The bind group of the trace kernels for `scene`, writing into `target`, built
    /// inside error scopes.
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        scene: &DeviceScene,
        target: &wgpu::TextureView,
    ) -> Result<wgpu::BindGroup, RenderError> {
        capture(device, "trace bind group", Caught::Resource, || {
            self.bind_group_unchecked(device, layout, scene, target)
        })
    }

    /// [`SlotBuffers::bind_group`] without error scopes (whose pops would block), for
    /// the frame loop: `layout` must be the renderer's trace layout and `target` an
    /// `Rgba32Float` storage texture.
    pub fn bind_group_unchecked(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        scene: &DeviceScene,
        target: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        fn buffer(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }
        }
        let s = &scene.buffers;
        let mut entries = vec![
            buffer(binding::FRAME, &self.uniforms),
            buffer(binding::SPHERES, &s.spheres),
            buffer(binding::PLANES, &s.planes),
            buffer(binding::POLYGONS, &s.polygons),
            buffer(binding::POLYGON_POINTS, &s.polygon_points),
            buffer(binding::TRIANGLES, &s.triangles),
            buffer(binding::MATERIALS, &s.materials),
            buffer(binding::LIGHTS, &s.lights),
            wgpu::BindGroupEntry {
                binding: binding::LINEAR_OUTPUT,
                resource: wgpu::BindingResource::TextureView(target),
            },
            buffer(binding::COUNTERS, &self.counters),
            buffer(binding::ACCUMULATION, &self.accumulation),
            wgpu::BindGroupEntry {
                binding: binding::IMAGES,
                resource: wgpu::BindingResource::TextureView(&scene.images),
            },
            buffer(binding::BVH_NODES, &s.bvh_nodes),
            buffer(binding::BVH_PRIMS, &s.bvh_prims),
            buffer(binding::PATHS, &self.paths),
            buffer(binding::RAY_STACK, &self.ray_stack),
            buffer(binding::TRACES, &self.traces),
            buffer(binding::TRAVERSAL_STACK, &self.traversal_stack),
            buffer(binding::TRIANGLE_ATTRIBUTES, &s.triangle_attributes),
            buffer(binding::EMITTERS, &s.emitters),
            buffer(binding::ENVIRONMENT, &s.environment),
            wgpu::BindGroupEntry {
                binding: binding::NODE_TEXELS,
                resource: wgpu::BindingResource::TextureView(&scene.node_texels),
            },
        ];
        if let Some(acceleration) = &scene.acceleration {
            entries.push(wgpu::BindGroupEntry {
                binding: binding::SCENE_TLAS,
                resource: wgpu::BindingResource::AccelerationStructure(&acceleration.tlas),
            });
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gpu-render trace bind group"),
            layout,
            entries: &entries,
        })
    }
}

/// What one region's trace measured.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct TraceOutcome {
    /// Rays traced.
    pub rays: u64,
    /// Wall time of the submissions.
    pub elapsed: Duration,
    /// GPU time of the trace passes, where the device has timestamp queries.
    pub gpu_time: Option<Duration>,
    /// Submissions and rounds it took.
    pub submissions: u32,
    /// Rounds (one dispatch of each kernel) it took.
    pub rounds: u64,
}

/// Traces every pixel of the region `frame` names (its region, target origin, sample
/// range, slot count and budget filled in) into `target`, blocking until done;
/// `report(pixels)` is told the newly finished pixels after each submission.
#[allow(clippy::too_many_arguments)]
pub(crate) fn trace_region(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    pipelines: &TracePipelines,
    slots: &SlotBuffers,
    bind_group: &wgpu::BindGroup,
    frame: &FrameUniforms,
    timeout: Option<Duration>,
    report: &dyn Fn(u64),
) -> Result<TraceOutcome, RenderError> {
    let pixels = u64::from(frame.region_width) * u64::from(frame.region_height);
    let mut outcome = TraceOutcome::default();
    if pixels == 0 {
        return Ok(outcome);
    }
    let frame = &FrameUniforms {
        static_pixels: static_pixels_for(frame, pixels),
        ..*frame
    };
    queue.write_buffer(&slots.uniforms, 0, bytemuck::bytes_of(frame));
    let groups = frame.slot_count.div_ceil(SLOT_WORKGROUP_SIZE);
    let period_ns = f64::from(queue.get_timestamp_period());
    let mut rounds = 4u32;
    let mut done = 0u64;
    let mut gpu_ns = 0.0f64;
    let mut first = true;
    let start = Instant::now();
    while done < pixels {
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render trace rounds"),
        });
        if first {
            // Zeroed slots start at PHASE_FIRST_PIXEL with no trace pending.
            encoder.clear_buffer(&slots.paths, 0, None);
            encoder.clear_buffer(&slots.traces, 0, None);
            encoder.clear_buffer(&slots.counters, 0, None);
            first = false;
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("gpu-render trace"),
                timestamp_writes: slots.timestamps.as_ref().map(|(set, _)| {
                    wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(0),
                        end_of_pass_write_index: Some(1),
                    }
                }),
            });
            encode_rounds(&mut pass, pipelines, bind_group, groups, rounds);
        }
        encoder.copy_buffer_to_buffer(
            &slots.counters,
            0,
            &slots.readback,
            0,
            size_of::<GpuCounters>() as u64,
        );
        if let Some((set, resolve)) = &slots.timestamps {
            encoder.resolve_query_set(set, 0..2, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, &slots.readback, 256, 16);
        }
        let submitted = Instant::now();
        submit_and_wait(device, queue, encoder, "trace rounds", timeout)?;
        let took = submitted.elapsed();
        let bytes = map_read(device, &slots.readback, READBACK_SIZE, timeout)?;
        let counters: GpuCounters =
            bytemuck::pod_read_unaligned(&bytes[..size_of::<GpuCounters>()]);
        outcome.submissions += 1;
        outcome.rounds += u64::from(rounds);
        if slots.timestamps.is_some() {
            let tick =
                |at: usize| u64::from_ne_bytes(bytes[at..at + 8].try_into().unwrap_or([0; 8]));
            let (begin, end) = (tick(256), tick(264));
            gpu_ns += end.saturating_sub(begin) as f64 * period_ns;
        }
        check_errors(counters.errors)?;
        let finished = u64::from(counters.pixels_done).min(pixels);
        if finished > done {
            report(finished - done);
            done = finished;
        }
        outcome.rays = counters.rays();
        // Aim at TARGET_SUBMISSION per submission, growing at most 4x at a time.
        let ratio = TARGET_SUBMISSION.as_secs_f64() / took.as_secs_f64().max(1e-6);
        let next = (f64::from(rounds) * ratio.clamp(0.25, 4.0)).round();
        rounds = (next as u32).clamp(1, MAX_ROUNDS);
    }
    outcome.elapsed = start.elapsed();
    outcome.gpu_time = (slots.timestamps.is_some() && period_ns.is_finite() && period_ns > 0.0)
        .then(|| Duration::from_secs_f64(gpu_ns * 1e-9));
    Ok(outcome)
}

/// Records `rounds` rounds of the trace kernels over `groups` workgroups of slots into
/// `pass`: each round one dispatch of `shade_paths` and one of `trace_rays`
/// (wavefront), or one of `trace_paths` (fused).
pub(crate) fn encode_rounds(
    pass: &mut wgpu::ComputePass<'_>,
    pipelines: &TracePipelines,
    bind_group: &wgpu::BindGroup,
    groups: u32,
    rounds: u32,
) {
    pass.set_bind_group(0, bind_group, &[]);
    let round = pipelines.round();
    for _ in 0..rounds {
        for pipeline in &round {
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(groups, 1, 1);
        }
    }
}

/// How long one kernel took to compile: its entry point and the time of its first
/// dispatch over no work at upload, which is the compile on drivers that compile
/// there (lavapipe) and nearly nothing on those that compiled at creation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelCompile {
    /// The kernel's entry point (`trace_paths`, `shade_paths`, `trace_rays`).
    pub entry_point: &'static str,
    /// Its first dispatch's time on the host, waiting for the device.
    pub time: Duration,
}

/// Runs each trace kernel of `pipelines` (those of its schedule) once over no slots
/// (`slot_count` 0: every invocation returns at once), so that a driver that compiles
/// a pipeline at its first dispatch rather than at its creation (lavapipe: LLVM,
/// seconds for a trace module) compiles it now, at upload, and neither the first
/// trace's time nor the first frame of a frame loop pays for it. Each kernel is
/// submitted and waited for alone, so that each one's compile is timed.
pub(crate) fn warm_up(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    pipelines: &TracePipelines,
    layout: &wgpu::BindGroupLayout,
    scene: &DeviceScene,
    timeout: Option<Duration>,
) -> Result<Vec<KernelCompile>, RenderError> {
    let slots = SlotBuffers::new(device, 1, scene.stack_size, 0, false)?;
    let target = create_texture(
        device,
        "gpu-render warm-up target",
        1,
        1,
        LINEAR_FORMAT,
        wgpu::TextureUsages::STORAGE_BINDING,
    )?;
    let view = target.create_view(&wgpu::TextureViewDescriptor::default());
    let bind_group = slots.bind_group(device, layout, scene, &view)?;
    let frame = FrameUniforms {
        slot_count: 0,
        ..scene.frame
    };
    queue.write_buffer(&slots.uniforms, 0, bytemuck::bytes_of(&frame));
    let mut compiled = Vec::new();
    for (entry_point, pipeline) in pipelines.named_round() {
        let started = std::time::Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render warm-up"),
        });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("gpu-render warm-up"),
                timestamp_writes: None,
            });
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(1, 1, 1);
        }
        submit_and_wait(device, queue, encoder, "warm-up dispatch", timeout)?;
        compiled.push(KernelCompile {
            entry_point,
            time: started.elapsed(),
        });
    }
    Ok(compiled)
}

/// Turns the kernels' error bits into an error: an image with a cut loop or an
/// overflowing traversal stack would be silently wrong, so none is returned.
pub(crate) fn check_errors(errors: u32) -> Result<(), RenderError> {
    if errors & ERROR_LOOP_CUT != 0 {
        return Err(RenderError::TraceIncomplete(TraceFailure::LoopCut));
    }
    if errors & ERROR_TRAVERSAL_STACK != 0 {
        return Err(RenderError::TraceIncomplete(TraceFailure::TraversalStack {
            max_depth: MAX_TRAVERSAL_STACK,
        }));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_devices_get_slots_per_host_thread_from_two_threads_up_to_the_gpu_count() {
        assert_eq!(cpu_slot_count(1), 2 * CPU_SLOTS_PER_THREAD);
        assert_eq!(cpu_slot_count(2), 4096);
        assert_eq!(cpu_slot_count(8), 16384);
        assert_eq!(cpu_slot_count(1000), 1 << 17);
        assert_eq!(cpu_slot_count(usize::MAX), 1 << 17);
    }

    fn llvmpipe(driver_info: &str) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
            driver: "llvmpipe".into(),
            driver_info: driver_info.into(),
            ..wgpu::AdapterInfo::new(wgpu::DeviceType::Cpu, wgpu::Backend::Vulkan)
        }
    }

    #[test]
    fn the_loop_limit_belongs_to_old_llvmpipes() {
        let old = llvmpipe("Mesa 22.3.6 (LLVM 15.0.6)");
        assert_eq!(driver_loop_limit(&old), Some(LLVMPIPE_LOOP_LIMIT));
        // 8 lanes of a 256-bit vector share the limit.
        assert_eq!(iteration_budget_for(&old), 65_535 / 8 - 2048);
        let new = llvmpipe("Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)");
        assert_eq!(mesa_version(&new), Some((25, 0)));
        assert_eq!(driver_loop_limit(&new), None);
        assert_eq!(iteration_budget_for(&new), 1 << 20);
        assert_eq!(driver_loop_limit(&llvmpipe("")), Some(LLVMPIPE_LOOP_LIMIT));
        let gpu = wgpu::AdapterInfo::new(wgpu::DeviceType::DiscreteGpu, wgpu::Backend::Vulkan);
        assert_eq!(driver_loop_limit(&gpu), None);
    }
}
