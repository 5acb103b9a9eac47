//! Headless rendering: the app's own frame run by egui_kittest's harness on wgpu and read back as an image, so a
//! render shows exactly what the app shows. wgpu takes a GPU when there is one and Mesa's software rasteriser
//! (llvmpipe through EGL) when there is none; no display is needed either way.

mod compare;
mod gpu;

use egui_kittest::Harness;
use egui_kittest::wgpu::WgpuTestRenderer;
use image::RgbaImage;

pub use compare::{Difference, PIXEL_THRESHOLD, compare};

use crate::app::{BonescopeApp, Chrome};

/// Why a picture could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("cannot render: {0}")]
    Gpu(String),
    #[error("cannot render a {width}×{height} picture: both sides must be 1 to 8192 pixels")]
    Size { width: u32, height: u32 },
}

/// The largest side wgpu's software rasteriser is sure to accept.
const MAX_SIDE: u32 = 8192;

/// Frames run before the first picture: the whole-clip analysis lands and the plots fit their bounds to it.
const WARM_UP_FRAMES: usize = 8;

/// Renders one app (its document, settings, selection and chrome) at chosen times, reusing one GPU context.
pub struct Renderer {
    harness: Harness<'static, BonescopeApp>,
}

impl Renderer {
    /// A `width`×`height` window (logical points at one pixel per point) showing `app`.
    pub fn new(app: BonescopeApp, width: u32, height: u32) -> Result<Self, RenderError> {
        if !(1..=MAX_SIDE).contains(&width) || !(1..=MAX_SIDE).contains(&height) {
            return Err(RenderError::Size { width, height });
        }
        let mut harness = Harness::builder()
            .with_size(egui::vec2(width as f32, height as f32))
            .with_pixels_per_point(1.0)
            .with_render_cursor(false)
            // Bone names in any script: a glyph the built-in fonts lack draws as a box, as in the app.
            .allow_missing_glyphs()
            .renderer(WgpuTestRenderer::from_render_state(gpu::render_state()?))
            .build_eframe(move |_cc| app);
        harness.step();
        let ctx = harness.ctx.clone();
        if harness.state().chrome == Chrome::Window {
            harness.state_mut().settle(&ctx);
        }
        harness.run_steps(WARM_UP_FRAMES);
        Ok(Renderer { harness })
    }

    /// The picture at `time` (seconds).
    pub fn render(&mut self, time: f64) -> Result<RgbaImage, RenderError> {
        self.harness.state_mut().time = time;
        // Two frames: the first lays out with the new time, the second paints what the first laid out.
        self.harness.run_steps(2);
        self.harness.render().map_err(RenderError::Gpu)
    }

    pub fn app(&self) -> &BonescopeApp {
        self.harness.state()
    }
}
