//! Comparing a render with a reference picture the way the snapshot tests do: a pixel differs when its perceptual
//! (YIQ) colour distance passes kittest's default threshold and it is not mere anti-aliasing (dify's test).

use image::RgbaImage;

/// Per-pixel YIQ distance above which a pixel counts as different: kittest's default snapshot threshold.
pub const PIXEL_THRESHOLD: f32 = 0.6;

/// How far a picture is from its reference.
#[derive(Debug)]
pub struct Difference {
    /// Pixels that differ (all of them when the sizes differ).
    pub differing: u64,
    pub total: u64,
    /// The reference faded to grey with differing pixels red (anti-aliasing differences yellow); `None` when the
    /// sizes differ.
    pub image: Option<RgbaImage>,
    /// `(width, height)` of the reference and of the render, when they differ.
    pub sizes: Option<([u32; 2], [u32; 2])>,
}

impl Difference {
    /// The share of differing pixels, in percent: the measure `--threshold` bounds.
    pub fn percent(&self) -> f64 {
        if self.total == 0 { 0.0 } else { self.differing as f64 * 100.0 / self.total as f64 }
    }
}

/// How much of the picture stays visible under the red marks of the diff image.
const UNCHANGED_BLEND: f32 = 0.1;

/// Compares `rendered` with `reference`.
pub fn pixel_difference(reference: &RgbaImage, rendered: &RgbaImage) -> Difference {
    let total = u64::from(reference.width()) * u64::from(reference.height());
    if reference.dimensions() != rendered.dimensions() {
        let (w, h) = reference.dimensions();
        let (rw, rh) = rendered.dimensions();
        return Difference {
            differing: total.max(1),
            total: total.max(1),
            image: None,
            sizes: Some(([w, h], [rw, rh])),
        };
    }
    let result = dify::diff::get_results(
        reference.clone(),
        rendered.clone(),
        PIXEL_THRESHOLD,
        true,
        Some(UNCHANGED_BLEND),
        &None,
        &None,
    );
    // With a blend factor dify always returns an image; the fallback only keeps this total.
    let (differing, image) =
        result.map_or_else(|| (0, reference.clone()), |(count, image)| (u64::try_from(count).unwrap_or(0), image));
    Difference { differing, total, image: Some(image), sizes: None }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    fn picture(w: u32, h: u32, colour: [u8; 4]) -> RgbaImage {
        RgbaImage::from_pixel(w, h, Rgba(colour))
    }

    #[test]
    fn identical_pictures_do_not_differ() {
        let a = picture(8, 4, [10, 20, 30, 255]);
        let d = pixel_difference(&a, &a.clone());
        assert_eq!((d.differing, d.total, d.percent()), (0, 32, 0.0));
    }

    #[test]
    fn changed_pixels_are_counted_and_marked_red() {
        let a = picture(10, 10, [0, 0, 0, 255]);
        let mut b = a.clone();
        for x in 0..10 {
            b.put_pixel(x, 5, Rgba([255, 255, 255, 255]));
        }
        let d = pixel_difference(&a, &b);
        assert_eq!(d.differing, 10);
        assert!((d.percent() - 10.0).abs() < 1e-12);
        let diff = d.image.expect("a diff image");
        assert_eq!(*diff.get_pixel(3, 5), Rgba([255, 0, 0, 255]));
        assert_ne!(*diff.get_pixel(3, 2), Rgba([255, 0, 0, 255]));
    }

    #[test]
    fn a_barely_changed_colour_is_not_a_difference() {
        let a = picture(4, 4, [100, 100, 100, 255]);
        let b = picture(4, 4, [100, 100, 101, 255]);
        assert_eq!(pixel_difference(&a, &b).differing, 0);
    }

    #[test]
    fn different_sizes_differ_everywhere() {
        let d = pixel_difference(&picture(4, 4, [0; 4]), &picture(4, 5, [0; 4]));
        assert_eq!((d.differing, d.total), (16, 16));
        assert_eq!(d.sizes, Some(([4, 4], [4, 5])));
        assert!(d.image.is_none());
    }
}
