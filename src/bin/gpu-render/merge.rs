//! `gpu-render merge TILE.exr... -o OUT`: the tiles of `--tile` or `--crop` renders
//! assembled into the whole image, written as the whole render would have been.

use anyhow::Result;
use gpu_render::low_level::echo::echo;
use gpu_render::output;
use gpu_render::tiles::merge_tiles;

use crate::args::MergeArgs;

/// Checks the output, merges the tiles (which checks that they cover the image once
/// and agree on what they render) and writes the image.
pub fn run(args: &MergeArgs) -> Result<()> {
    output::check_output_path(&args.output)?;
    output::check_not_an_input(
        &args.output,
        args.tiles.iter().map(|tile| (tile.as_path(), "tile")),
    )?;
    let merged = merge_tiles(&args.tiles)?;
    let written = output::write_image(&args.output, &merged.image, &merged.display_rgba8)?;
    if !args.quiet {
        crate::warn_clamped(&args.output, written);
        if merged.devices.len() > 1 {
            // The devices' names, as every word a tile records, are quoted from files.
            let devices: Vec<String> = merged
                .devices
                .iter()
                .map(|device| echo(device).to_string())
                .collect();
            eprintln!(
                "warning: the tiles were rendered on {} different devices ({}); GPUs of other \
                 makes may round the last bits of a pixel differently",
                merged.devices.len(),
                devices.join(", ")
            );
        }
        let info = &merged.info;
        let frame = info
            .frame
            .map_or(String::new(), |frame| format!(", frame {frame}"));
        eprintln!(
            "merged {} tiles into {}x{} ({}{frame}; {}; {}) -> {}",
            args.tiles.len(),
            info.image_width,
            info.image_height,
            echo(&info.scene_name),
            echo(&info.settings),
            echo(&info.backend),
            args.output.display()
        );
    }
    Ok(())
}
