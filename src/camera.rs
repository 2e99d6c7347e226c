//! The camera and the screen rectangle it looks through: one primary ray per pixel.

use crate::ray::Ray;
use crate::real::{Num, Real, Vector};
use crate::Vec3;

/// The screen: an axis-aligned rectangle in the plane `z = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Screen {
    /// x of the left edge.
    pub left: f64,
    /// x of the right edge (greater than `left`).
    pub right: f64,
    /// y of the top edge (greater than `bottom`).
    pub top: f64,
    /// y of the bottom edge.
    pub bottom: f64,
}

impl Screen {
    /// The tutorial's screen for an image of `width` × `height` pixels:
    /// x from -1 to 1 and y from -1/ratio to 1/ratio, with ratio = width / height,
    /// so that pixels are square.
    pub fn for_image(width: u32, height: u32) -> Screen {
        let ratio = f64::from(width) / f64::from(height);
        Screen {
            left: -1.0,
            right: 1.0,
            top: 1.0 / ratio,
            bottom: -1.0 / ratio,
        }
    }
}

/// An eye at `position` looking through `screen`, sampled by `width` × `height` pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The eye: every primary ray starts here.
    pub position: Vec3,
    /// The rectangle the eye looks through.
    pub screen: Screen,
    /// Columns of the image.
    pub width: u32,
    /// Rows of the image.
    pub height: u32,
}

// ANCHOR: primary_ray
impl Camera {
    /// The point of the screen that pixel (`row` from the top, `col` from the left)
    /// looks at, computed in precision `T`. As in the tutorial, the first and last
    /// pixels sit exactly on the screen's edges: `x` is sample `col` of
    /// `linspace(left, right, W)`.
    #[inline]
    pub fn screen_point<T: Real>(&self, row: u32, col: u32) -> T::Vec3 {
        let s = &self.screen;
        let x = linspace(T::of(s.left), T::of(s.right), col, self.width);
        let y = linspace(T::of(s.top), T::of(s.bottom), row, self.height);
        T::Vec3::new(x, y, T::of(0.0))
    }

    /// The ray from the eye through the pixel's screen point.
    #[inline]
    pub fn primary_ray<T: Real>(&self, row: u32, col: u32) -> Ray<T> {
        Ray::towards(T::Vec3::of(self.position), self.screen_point::<T>(row, col))
    }
    // ANCHOR_END: primary_ray

    /// The ray from the eye through a position between pixels (for samples).
    #[inline]
    pub fn ray_through<T: Real>(&self, row: f64, col: f64) -> Ray<T> {
        Ray::towards(
            T::Vec3::of(self.position),
            self.screen_point_at::<T>(row, col),
        )
    }

    /// The screen at a position between pixels too (`row` 2.25 is a quarter of
    /// the way from row 2 to row 3), on the same grid as [`Camera::screen_point`].
    #[inline]
    pub fn screen_point_at<T: Real>(&self, row: f64, col: f64) -> T::Vec3 {
        let s = &self.screen;
        let x = lerp_on_grid(T::of(s.left), T::of(s.right), T::of(col), self.width);
        let y = lerp_on_grid(T::of(s.top), T::of(s.bottom), T::of(row), self.height);
        T::Vec3::new(x, y, T::of(0.0))
    }
}

// ANCHOR: linspace
/// Sample `i` of numpy's `linspace(from, to, n)`, computed as numpy computes it:
/// `from + i·step` with `step = (to − from)/(n − 1)`, and the last sample exactly
/// `to`. (numpy also has a branch for a step that underflows to zero, which no
/// screen of raystep's has.)
#[inline(always)]
pub fn linspace<T: Real>(from: T, to: T, i: u32, n: u32) -> T {
    if n > 1 && i == n - 1 {
        return to;
    }
    lerp_on_grid(from, to, T::of(f64::from(i)), n)
}

/// Position `i` (a whole number or between two) on the grid of `n` evenly spaced
/// values from `from` to `to`: `from + i·step`, a single sample being `from`. (For
/// any [`Num`]: the fast engine places four samples at once with it.)
#[inline(always)]
pub fn lerp_on_grid<N: Num>(from: N, to: N, i: N, n: u32) -> N {
    if n < 2 {
        return from;
    }
    let step = (to - from) / N::of(f64::from(n - 1));
    from + i * step
}
// ANCHOR_END: linspace

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(width: u32, height: u32) -> Camera {
        Camera {
            position: Vec3::new(0.0, 0.0, 1.0),
            screen: Screen::for_image(width, height),
            width,
            height,
        }
    }

    #[test]
    fn corner_pixels_sit_on_the_screen_corners() {
        let cam = camera(300, 200);
        assert_eq!(
            cam.screen_point::<f64>(0, 0),
            Vec3::new(-1.0, 2.0 / 3.0, 0.0)
        );
        assert_eq!(
            cam.screen_point::<f64>(199, 299),
            Vec3::new(1.0, -2.0 / 3.0, 0.0)
        );
    }

    #[test]
    fn the_grid_is_numpys_linspace_to_the_last_bit() {
        // np.linspace(0, 1, 11): 3·0.1 rounds to 0.30000000000000004 and 7·0.1 to
        // 0.7000000000000001 (a division 3/10 would give 0.3); the last is 1 exactly.
        assert_eq!(linspace(0.0, 1.0, 3, 11), 0.30000000000000004);
        assert_eq!(linspace(0.0, 1.0, 7, 11), 0.7000000000000001);
        assert_eq!(linspace(0.0, 1.0, 10, 11), 1.0);
        // Without the last sample set to `to`, 1919 steps of 2/1919 from -1 miss 1.
        let step = 2.0 / 1919.0;
        assert_ne!(-1.0 + 1919.0 * step, 1.0);
        assert_eq!(linspace(-1.0, 1.0, 1919, 1920), 1.0);
        assert_eq!(linspace(-1.0f32, 1.0, 0, 1), -1.0);
        // Chapter 2's count: of 1920 columns, this many would move by dividing last.
        // Python's floats give the same 927: `step = 2/1919; g = [-1 + j*step for j
        // in range(1920)]; g[-1] = 1.0; sum(g[j] != -1 + j*2/1919 for j in range(1920))`.
        let divided_last = (0..1920u32)
            .filter(|&j| linspace(-1.0, 1.0, j, 1920) != -1.0 + f64::from(j) * 2.0 / 1919.0)
            .count();
        assert_eq!(divided_last, 927);
    }

    #[test]
    fn a_one_pixel_image_looks_at_the_top_left_corner_as_linspace_does() {
        // np.linspace(a, b, 1) is [a].
        let cam = camera(1, 1);
        assert_eq!(cam.screen_point::<f64>(0, 0), Vec3::new(-1.0, 1.0, 0.0));
        let d = Vec3::new(-1.0, 1.0, -1.0).normalize();
        assert!((cam.primary_ray::<f64>(0, 0).direction - d).length() < 1e-15);
        let d32 = cam.primary_ray::<f32>(0, 0).direction;
        assert!((glam::Vec3::new(-1.0, 1.0, -1.0).normalize() - d32).length() < 1e-6);
    }
}
