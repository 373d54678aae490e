//! Error scopes, bounded waits and readback: the host-side plumbing that turns wgpu's
//! panics and callbacks into [`RenderError`] values.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::mpsc;
use std::time::Duration;

use super::RenderError;

/// How validation and internal errors caught by [`capture`] are reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Caught {
    /// Shader module or pipeline creation: [`RenderError::Shader`].
    Shader,
    /// Anything else: [`RenderError::Wgpu`].
    Resource,
}

/// Runs `f` inside out-of-memory, validation and internal error scopes and returns its
/// value, or the first error wgpu reported. Without the scopes wgpu hands these errors
/// to the uncaptured-error handler, whose default panics.
///
/// Error scopes are per thread in wgpu (with `std`), and the guards are popped here on
/// the same thread, innermost first as the scope stack requires.
pub(crate) fn capture<T>(
    device: &wgpu::Device,
    what: &str,
    kind: Caught,
    f: impl FnOnce() -> T,
) -> Result<T, RenderError> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let internal = device.push_error_scope(wgpu::ErrorFilter::Internal);
    let value = f();
    let internal = pollster::block_on(internal.pop());
    let validation = pollster::block_on(validation.pop());
    let oom = pollster::block_on(oom.pop());
    if let Some(source) = oom {
        return Err(RenderError::OutOfMemory {
            what: what.to_owned(),
            source,
        });
    }
    if let Some(source) = validation.or(internal) {
        let what = what.to_owned();
        return Err(match kind {
            Caught::Shader => RenderError::Shader { what, source },
            Caught::Resource => RenderError::Wgpu { what, source },
        });
    }
    Ok(value)
}

/// Blocks until `submission` has finished, for at most `timeout` (`None`: as long as
/// it takes).
///
/// A timeout is reported as [`RenderError::Timeout`]: a dispatch that runs that long
/// has hung or been killed by a watchdog, and waiting forever is worse. wgpu panics
/// (rather than returning an error) when the device fails during the wait; that panic
/// is caught here and reported as a lost device too, so a driver reset cannot take the
/// whole process down.
pub(crate) fn wait(
    device: &wgpu::Device,
    submission: wgpu::SubmissionIndex,
    timeout: Option<Duration>,
) -> Result<(), RenderError> {
    let poll = catch_unwind(AssertUnwindSafe(|| {
        device.poll(wgpu::PollType::Wait {
            submission_index: Some(submission),
            timeout,
        })
    }));
    match poll {
        Ok(Ok(_)) => Ok(()),
        Ok(Err(wgpu::PollError::Timeout)) => Err(RenderError::Timeout(timeout.unwrap_or_default())),
        Ok(Err(e)) => Err(RenderError::DeviceLost(e.to_string())),
        Err(panic) => {
            let message = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "device poll failed".to_string());
            Err(RenderError::DeviceLost(message))
        }
    }
}

/// Submits `encoder` inside error scopes and waits for it.
pub(crate) fn submit_and_wait(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    encoder: wgpu::CommandEncoder,
    what: &str,
    timeout: Option<Duration>,
) -> Result<(), RenderError> {
    let submission = capture(device, what, Caught::Resource, || {
        queue.submit([encoder.finish()])
    })?;
    wait(device, submission, timeout)
}

/// Maps `buffer` (MAP_READ, not in use) for reading, copies `size` bytes out, unmaps.
pub(crate) fn map_read(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    size: u64,
    timeout: Option<Duration>,
) -> Result<Vec<u8>, RenderError> {
    let (sender, receiver) = mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, 0..size, move |result| {
        // The receiver outlives the wait below; if it is gone nobody needs the result.
        let _ = sender.send(result);
    });
    // The map callback fires from inside poll; the map is resolved once poll returns.
    let poll = catch_unwind(AssertUnwindSafe(|| {
        device.poll(wgpu::PollType::Wait {
            submission_index: None,
            timeout,
        })
    }));
    match poll {
        Ok(Ok(_)) => {}
        Ok(Err(wgpu::PollError::Timeout)) => {
            return Err(RenderError::Timeout(timeout.unwrap_or_default()));
        }
        Ok(Err(e)) => return Err(RenderError::DeviceLost(format!("waiting for a map: {e}"))),
        Err(_) => {
            return Err(RenderError::DeviceLost(
                "device failed while mapping".into(),
            ));
        }
    }
    match receiver.try_recv() {
        Ok(Ok(())) => {}
        Ok(Err(e)) => {
            return Err(RenderError::Readback {
                what: format!("map failed: {e}"),
                source: Some(e),
            });
        }
        Err(_) => {
            return Err(RenderError::Readback {
                what: "the map did not complete".into(),
                source: None,
            });
        }
    }
    let bytes = buffer
        .get_mapped_range(0..size)
        .map_err(|e| RenderError::Readback {
            what: format!("mapped range: {e}"),
            source: None,
        })?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// `value` rounded up to a multiple of `alignment` (a power of two).
pub(crate) fn align_up(value: u64, alignment: u64) -> u64 {
    value.div_ceil(alignment) * alignment
}

/// Largest staging buffer used for texture readback. Textures are read in bands of
/// rows so that a 2^27-pixel float image never needs a 2 GiB mappable buffer (which
/// many devices' `max_buffer_size` forbids).
const READBACK_BAND_BYTES: u64 = 64 << 20;

/// Reads the whole first mip of a 2D `texture` (usage `COPY_SRC`) whose texels are
/// `bytes_per_texel` bytes (16 for `Rgba32Float`, 4 for `Rgba8Unorm`), returning tightly
/// packed rows, top row first. Rows are copied with `bytes_per_row` padded to wgpu's
/// 256-byte alignment and the padding is stripped; large textures are read in bands of
/// rows through one staging buffer of at most 64 MiB. Each wait is bounded by `timeout`.
///
/// Errors: [`RenderError::Readback`], [`RenderError::DeviceLost`], [`RenderError::OutOfMemory`].
///
/// ```no_run
/// # fn demo(device: &wgpu::Device, queue: &wgpu::Queue, texture: &wgpu::Texture)
/// # -> Result<(), gpu_render::gpu::RenderError> {
/// let rgba8 = gpu_render::gpu::read_texture(
///     device, queue, texture, 4, Some(std::time::Duration::from_secs(10)))?;
/// assert_eq!(rgba8.len(), (texture.width() * texture.height() * 4) as usize);
/// # Ok(())
/// # }
/// ```
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
    timeout: Option<Duration>,
) -> Result<Vec<u8>, RenderError> {
    let (width, height) = (texture.width(), texture.height());
    let row_bytes = u64::from(width) * u64::from(bytes_per_texel);
    let padded_row = align_up(row_bytes, u64::from(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT));
    let padded_row_u32 = u32::try_from(padded_row).map_err(|_| RenderError::Readback {
        what: format!("a row of {padded_row} bytes is too wide to copy"),
        source: None,
    })?;
    let band_rows = (READBACK_BAND_BYTES / padded_row).clamp(1, u64::from(height.max(1)));
    let staging_size = padded_row * band_rows;
    let staging = capture(device, "readback buffer", Caught::Resource, || {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("gpu-render readback"),
            size: staging_size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        })
    })?;
    let mut out = Vec::with_capacity((row_bytes * u64::from(height)) as usize);
    let mut row = 0u32;
    while row < height {
        // band_rows <= height, so it fits in u32.
        let rows = (band_rows as u32).min(height - row);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render readback copy"),
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x: 0, y: row, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &staging,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row_u32),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d {
                width,
                height: rows,
                depth_or_array_layers: 1,
            },
        );
        submit_and_wait(device, queue, encoder, "readback copy", timeout)?;
        let bytes = map_read(device, &staging, padded_row * u64::from(rows), timeout)?;
        for padded in bytes.chunks_exact(padded_row as usize) {
            out.extend_from_slice(&padded[..row_bytes as usize]);
        }
        row += rows;
    }
    Ok(out)
}

/// Reads the first `size` bytes of `buffer` (usage `COPY_SRC`, `size` a multiple of
/// 4) through a staging buffer of at most 64 MiB, in bands. Each wait is bounded by
/// `timeout`.
///
/// Errors: [`RenderError::Readback`], [`RenderError::DeviceLost`], [`RenderError::OutOfMemory`].
pub(crate) fn read_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    size: u64,
    timeout: Option<Duration>,
) -> Result<Vec<u8>, RenderError> {
    let band = READBACK_BAND_BYTES.min(size).max(4);
    let staging = capture(device, "readback buffer", Caught::Resource, || {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("gpu-render buffer readback"),
            size: band,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        })
    })?;
    let mut out = Vec::with_capacity(size as usize);
    let mut offset = 0;
    while offset < size {
        let bytes = band.min(size - offset);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("gpu-render buffer readback copy"),
        });
        encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, bytes);
        submit_and_wait(device, queue, encoder, "readback copy", timeout)?;
        out.extend_from_slice(&map_read(device, &staging, bytes, timeout)?);
        offset += bytes;
    }
    Ok(out)
}

/// Creates a 2D texture inside error scopes (allocation failure becomes
/// [`RenderError::OutOfMemory`]).
pub(crate) fn create_texture(
    device: &wgpu::Device,
    label: &str,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> Result<wgpu::Texture, RenderError> {
    capture(device, label, Caught::Resource, || {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    })
}

#[cfg(test)]
mod tests {
    use super::align_up;

    #[test]
    fn rows_pad_to_256_bytes() {
        assert_eq!(align_up(37 * 16, 256), 768);
        assert_eq!(align_up(37 * 4, 256), 256);
        assert_eq!(align_up(256, 256), 256);
        assert_eq!(align_up(0, 256), 0);
    }
}
