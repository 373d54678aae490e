//! The device limits the frame-loop renderer needs, checked before any pipeline is
//! built so that a device made with too small limits gets a [`RenderError::Limit`]
//! instead of a wgpu validation error outside an error scope (which the default
//! uncaptured-error handler turns into a panic).

use super::RenderError;
use super::pipelines::TRACE_STORAGE_BUFFERS;
use super::shaders::{SLOT_WORKGROUP_SIZE, WORKGROUP_SIZE};

/// Bindings in the trace kernels' bind group, counted to the highest index
/// (`shaders/trace.wgsl`, 0 to 18, `shaders/path.wgsl`'s 19,
/// `shaders/environment.wgsl`'s 20, the hardware traversal's 21 and the BVH node
/// texture's 22, `src/gpu/pipelines.rs`).
const TRACE_BINDINGS: u32 = 23;

/// One limit the renderer needs at least: the field of [`wgpu::Limits`] by name and
/// by accessor, and the minimum.
struct Need {
    limit: &'static str,
    field: fn(&mut wgpu::Limits) -> &mut u32,
    needed: u32,
}

/// The minimums every device must meet, whatever the scene: what the bind group
/// layouts and workgroup sizes of the trace, display and draw pipelines use.
const NEEDS: [Need; 9] = [
    Need {
        limit: "max_storage_buffers_per_shader_stage",
        field: |l| &mut l.max_storage_buffers_per_shader_stage,
        needed: TRACE_STORAGE_BUFFERS,
    },
    Need {
        limit: "max_storage_textures_per_shader_stage",
        field: |l| &mut l.max_storage_textures_per_shader_stage,
        // The linear output and the BVH node texture (a placeholder where unused).
        needed: 2,
    },
    Need {
        limit: "max_sampled_textures_per_shader_stage",
        field: |l| &mut l.max_sampled_textures_per_shader_stage,
        // The images.
        needed: 1,
    },
    Need {
        limit: "max_uniform_buffers_per_shader_stage",
        field: |l| &mut l.max_uniform_buffers_per_shader_stage,
        needed: 1,
    },
    Need {
        limit: "max_bindings_per_bind_group",
        field: |l| &mut l.max_bindings_per_bind_group,
        needed: TRACE_BINDINGS,
    },
    Need {
        limit: "max_compute_invocations_per_workgroup",
        field: |l| &mut l.max_compute_invocations_per_workgroup,
        needed: if SLOT_WORKGROUP_SIZE > WORKGROUP_SIZE * WORKGROUP_SIZE {
            SLOT_WORKGROUP_SIZE
        } else {
            WORKGROUP_SIZE * WORKGROUP_SIZE
        },
    },
    Need {
        limit: "max_compute_workgroup_size_x",
        field: |l| &mut l.max_compute_workgroup_size_x,
        needed: SLOT_WORKGROUP_SIZE,
    },
    Need {
        limit: "max_compute_workgroup_size_y",
        field: |l| &mut l.max_compute_workgroup_size_y,
        needed: WORKGROUP_SIZE,
    },
    Need {
        limit: "max_bind_groups",
        field: |l| &mut l.max_bind_groups,
        needed: 1,
    },
];

/// Checks `limits` (a device's) against what the renderer needs whatever the scene.
///
/// Errors: [`RenderError::Limit`] naming the first limit that is too small, what is
/// needed and what the device has.
pub fn check_limits(limits: &wgpu::Limits) -> Result<(), RenderError> {
    let mut copy = limits.clone();
    for need in &NEEDS {
        let available = *(need.field)(&mut copy);
        if available < need.needed {
            return Err(RenderError::Limit {
                limit: need.limit,
                needed: u64::from(need.needed),
                available: u64::from(available),
            });
        }
    }
    Ok(())
}

/// The limits to request for a device the renderer will use: `adapter_limits` (what
/// the adapter offers, so large scenes and films fit) raised to at least the
/// renderer's minimums. Where the adapter offers less than a minimum, the device
/// request fails, and wgpu names the limit.
pub fn required_limits(adapter_limits: &wgpu::Limits) -> wgpu::Limits {
    let mut limits = adapter_limits.clone();
    for need in &NEEDS {
        let field = (need.field)(&mut limits);
        *field = (*field).max(need.needed);
    }
    limits
}

/// The features of `adapter_features` worth requesting for a device the renderer
/// will use; it runs without them, only slower or with less to report:
/// [`wgpu::Features::TIMESTAMP_QUERY`] times the trace passes on the GPU
/// ([`crate::film::RenderStats::gpu_time`]), and [`wgpu::Features::SUBGROUP`] lets the
/// fused kernel's traversals give way to finished lanes where asked
/// ([`super::RendererOptions::refill_lanes`]), and [`wgpu::Features::PIPELINE_CACHE`]
/// lets an application keep compiled kernels between runs
/// ([`super::RendererOptions::pipeline_cache`]).
pub fn optional_features(adapter_features: wgpu::Features) -> wgpu::Features {
    adapter_features
        & (wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::SUBGROUP
            | wgpu::Features::PIPELINE_CACHE)
}

/// Checks that `needed` bytes fit one storage binding of a device with `limits`.
pub(crate) fn check_binding_bytes(limits: &wgpu::Limits, needed: u64) -> Result<(), RenderError> {
    let (limit, available) = if limits.max_storage_buffer_binding_size <= limits.max_buffer_size {
        (
            "max_storage_buffer_binding_size",
            limits.max_storage_buffer_binding_size,
        )
    } else {
        ("max_buffer_size", limits.max_buffer_size)
    };
    if needed > available {
        return Err(RenderError::Limit {
            limit,
            needed,
            available,
        });
    }
    Ok(())
}

/// Checks that a film of `width × height` fits one 2D texture of a device with
/// `limits`.
pub(crate) fn check_film_size(
    limits: &wgpu::Limits,
    width: u32,
    height: u32,
) -> Result<(), RenderError> {
    let side = width.max(height);
    if side > limits.max_texture_dimension_2d {
        return Err(RenderError::Limit {
            limit: "max_texture_dimension_2d",
            needed: u64::from(side),
            available: u64::from(limits.max_texture_dimension_2d),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_limits_name_the_storage_buffers() {
        let err = check_limits(&wgpu::Limits::default()).unwrap_err();
        match err {
            RenderError::Limit {
                limit,
                needed,
                available,
            } => {
                assert_eq!(limit, "max_storage_buffers_per_shader_stage");
                assert_eq!(needed, u64::from(TRACE_STORAGE_BUFFERS));
                assert_eq!(available, 8);
            }
            other => panic!("expected a limit error, got {other}"),
        }
    }

    #[test]
    fn required_limits_pass_the_check() {
        for base in [
            wgpu::Limits::default(),
            wgpu::Limits::downlevel_defaults(),
            wgpu::Limits::downlevel_webgl2_defaults(),
        ] {
            let limits = required_limits(&base);
            assert!(check_limits(&limits).is_ok(), "{limits:?}");
            // Nothing is lowered.
            assert!(limits.max_buffer_size >= base.max_buffer_size);
            assert_eq!(
                limits.max_texture_dimension_2d,
                base.max_texture_dimension_2d
            );
        }
    }
}
