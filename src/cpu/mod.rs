//! The CPU reference tracer: the same model as the WGSL shaders, with the same function
//! names, written plainly in `f64` so that it can serve as the oracle (being written).

use crate::film::{LinearImage, ProgressFn, RenderStats, Rendered};
use crate::scene::Scene;

/// Renders `scene` on all CPU cores. `progress` is told the number of finished rows.
pub fn render(scene: &Scene, progress: Option<ProgressFn<'_>>) -> Rendered {
    let _ = progress;
    Rendered {
        image: LinearImage::new(scene.render.width, scene.render.height),
        stats: RenderStats::default(),
    }
}
