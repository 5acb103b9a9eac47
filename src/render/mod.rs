//! Headless rendering: the app's own frame run by egui_kittest's harness on wgpu and read back as an image, so a
//! render shows exactly what the app shows. wgpu takes a GPU when there is one and Mesa's software rasteriser
//! (llvmpipe through EGL) when there is none; no display is needed either way.

mod compare;
mod gpu;

use egui_kittest::Harness;
use egui_kittest::wgpu::WgpuTestRenderer;
use image::RgbaImage;

pub use compare::{Difference, PIXEL_THRESHOLD, pixel_difference};

use egui::Color32;

use crate::app::{BonescopeApp, Chrome};
use crate::view::Palette;

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

/// What goes behind a viewport-only picture.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Background {
    /// The viewport's own colour, as in the app.
    #[default]
    Viewport,
    /// None: a PNG with an alpha channel, for compositing.
    Transparent,
}

/// Frames a window render runs at each new time before its picture is taken.
const WINDOW_SETTLE_FRAMES: usize = 3;

/// Renders one app (its document, settings, selection and chrome) at chosen times, reusing one GPU context.
pub struct Renderer {
    harness: Harness<'static, BonescopeApp>,
    background: Background,
}

impl Renderer {
    /// A `width`×`height` window (logical points at one pixel per point) showing `app`.
    pub fn new(app: BonescopeApp, width: u32, height: u32, background: Background) -> Result<Self, RenderError> {
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
        if harness.state().window.chrome == Chrome::Window {
            harness.state_mut().settle();
        }
        harness.run_steps(WARM_UP_FRAMES);
        Ok(Renderer { harness, background })
    }

    /// The picture at `time` (seconds).
    pub fn render(&mut self, time: f64) -> Result<RgbaImage, RenderError> {
        self.harness.state_mut().window.time = time;
        // The viewport evaluates the pose at the start of its frame and paints it in the same pass; the panels of
        // the window size themselves to their new content over the next frames.
        let frames = if self.app().window.chrome == Chrome::Window { WINDOW_SETTLE_FRAMES } else { 1 };
        self.harness.run_steps(frames);
        let mut image = self.harness.render().map_err(RenderError::Gpu)?;
        // The whole window paints its own panels; the viewport alone is drawn without its background.
        if self.app().window.chrome == Chrome::ViewportOnly {
            match self.background {
                Background::Viewport => composite(&mut image, Palette::new(self.app().settings.dark).background),
                Background::Transparent => unpremultiply(&mut image),
            }
        }
        Ok(image)
    }

    pub fn app(&self) -> &BonescopeApp {
        self.harness.state()
    }
}

/// Puts an opaque `background` behind a picture of premultiplied colours: `C = C_picture + background·(1 − α)`,
/// what the GPU's blending would have made had the background been drawn first.
fn composite(image: &mut RgbaImage, background: Color32) {
    let behind = background.to_array();
    for pixel in image.pixels_mut() {
        let uncovered = 255 - u16::from(pixel[3]);
        for c in 0..3 {
            let under = (u16::from(behind[c]) * uncovered + 127) / 255;
            pixel[c] = u8::try_from(u16::from(pixel[c]) + under).unwrap_or(u8::MAX);
        }
        pixel[3] = 255;
    }
}

/// Premultiplied colours to the straight alpha PNG stores.
fn unpremultiply(image: &mut RgbaImage) {
    for pixel in image.pixels_mut() {
        let alpha = u16::from(pixel[3]);
        for c in 0..3 {
            if let Some(straight) = (u16::from(pixel[c]) * 255 + alpha / 2).checked_div(alpha) {
                pixel[c] = u8::try_from(straight).unwrap_or(u8::MAX);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    #[test]
    fn compositing_is_the_over_operator_on_premultiplied_colours() {
        // Half-covered pure red (premultiplied 128, 0, 0, 128) over blue (0, 0, 200).
        let mut image = RgbaImage::from_pixel(2, 1, Rgba([128, 0, 0, 128]));
        image.put_pixel(1, 0, Rgba([0, 0, 0, 0]));
        composite(&mut image, Color32::from_rgb(0, 0, 200));
        assert_eq!(image.get_pixel(0, 0).0, [128, 0, 100, 255]);
        assert_eq!(image.get_pixel(1, 0).0, [0, 0, 200, 255]);
    }

    #[test]
    fn unpremultiplying_restores_straight_colours() {
        let mut image = RgbaImage::from_pixel(2, 1, Rgba([64, 32, 0, 128]));
        image.put_pixel(1, 0, Rgba([0, 0, 0, 0]));
        unpremultiply(&mut image);
        assert_eq!(image.get_pixel(0, 0).0, [128, 64, 0, 128]);
        assert_eq!(image.get_pixel(1, 0).0, [0, 0, 0, 0]);
    }
}
