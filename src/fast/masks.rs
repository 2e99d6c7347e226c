//! Tile masks: for each tile of 16 × 8 pixels, the objects its primary rays can
//! hit. Every primary ray starts at the camera, so the rays of a tile lie inside a
//! pyramid with its apex at the camera; an object entirely outside that pyramid
//! cannot be hit by any of them. The test is made with a margin larger than any
//! rounding of the intersection test itself, so a masked-out object is one the
//! test would have missed anyway: the masks never change a pixel. The fast engine
//! reads them; the book's tracer does not.

use crate::camera::Camera;
use crate::real::{Real, Vector};
use crate::scene::{Object, Shape};
use crate::Vec3;

/// Every object: the search mask that skips none.
pub const EVERY: u64 = u64::MAX;

/// Tile width and height, in pixels.
pub const TILE: (u32, u32) = (16, 8);

/// For each tile of the image, the objects its primary rays can hit: bit `i` set
/// means object `i` must be tested. Only for scenes of at most 64 objects (larger
/// ones use the BVH, or the book's engine); [`TileMasks::mask`] gives every bit
/// when there are none.
#[derive(Clone, Debug, Default)]
pub struct TileMasks {
    columns: u32,
    masks: Vec<u64>,
}

impl TileMasks {
    /// No masks: every object is tested.
    pub fn none() -> TileMasks {
        TileMasks::default()
    }

    /// The masks of `camera`'s tiles for `objects`, computed in precision `T`'s
    /// rounding (the margin grows with it).
    pub fn new<T: Real>(camera: &Camera, objects: &[Object<T>]) -> TileMasks {
        if objects.len() > 64 || camera.width < 2 || camera.height < 2 {
            return TileMasks::none();
        }
        let columns = camera.width.div_ceil(TILE.0);
        let rows = camera.height.div_ceil(TILE.1);
        let origin = camera.position;
        // Spheres as centre and an effective radius: the radius plus the widest
        // false hit the rounding of either intersection method could report (the
        // textbook quadratic's error in Δ grows with |O − C|²; 256·u of it covers
        // both methods with room to spare).
        let u = T::UNIT_ROUNDOFF.to_f64();
        let spheres: Vec<Option<(Vec3, f64)>> = objects
            .iter()
            .map(|o| match o.shape {
                Shape::Sphere(s) => {
                    let (c, r) = (s.center.to_f64(), s.radius.to_f64());
                    let reach = (c - origin).length() + r;
                    Some((c, (r * r + 256.0 * u * reach * reach).sqrt() * (1.0 + 1e-9)))
                }
                Shape::Plane(_) => None,
            })
            .collect();
        let mut masks = Vec::with_capacity((columns * rows) as usize);
        for tile_row in 0..rows {
            for tile_col in 0..columns {
                // The tile's corners, half a pixel outside its outer pixels, so the
                // jittered samples of --spp lie inside too.
                let r0 = f64::from(tile_row * TILE.1) - 0.5;
                let r1 = f64::from(((tile_row + 1) * TILE.1).min(camera.height) - 1) + 0.5;
                let c0 = f64::from(tile_col * TILE.0) - 0.5;
                let c1 = f64::from(((tile_col + 1) * TILE.0).min(camera.width) - 1) + 0.5;
                let corners = [
                    camera.screen_point_at::<f64>(r0, c0) - origin,
                    camera.screen_point_at::<f64>(r0, c1) - origin,
                    camera.screen_point_at::<f64>(r1, c1) - origin,
                    camera.screen_point_at::<f64>(r1, c0) - origin,
                ];
                let edge = |i: usize| (corners[i], corners[(i + 1) % 4]);
                // Edges less than 1e-6 apart in angle (a screen almost without
                // height or width) give planes whose rounding the margin does not
                // cover: such a tile gets no mask.
                let wide = (0..4).all(|i| {
                    let (a, b) = edge(i);
                    a.cross(b).length() >= 1e-6 * a.length() * b.length()
                });
                if !wide {
                    masks.push(EVERY);
                    continue;
                }
                let inside = corners.iter().fold(Vec3::ZERO, |a, &c| a + c);
                let planes: [Vec3; 4] = std::array::from_fn(|i| {
                    let (a, b) = edge(i);
                    let n = a.cross(b).normalize();
                    if n.dot(inside) < 0.0 {
                        -n
                    } else {
                        n
                    }
                });
                // ANCHOR: tile_test
                let mut mask = 0u64;
                for (i, sphere) in spheres.iter().enumerate() {
                    let candidate = match sphere {
                        None => true,
                        Some((c, reach)) => planes.iter().all(|n| n.dot(*c - origin) >= -reach),
                    };
                    if candidate {
                        mask |= 1 << i;
                    }
                }
                // ANCHOR_END: tile_test
                masks.push(mask);
            }
        }
        TileMasks { columns, masks }
    }

    /// The objects pixel (`row`, `col`)'s primary rays can hit.
    #[inline]
    pub fn mask(&self, row: u32, col: u32) -> u64 {
        if self.masks.is_empty() {
            return EVERY;
        }
        self.masks[((row / TILE.1) * self.columns + col / TILE.0) as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_ball as ball;
    use crate::camera::Screen;

    /// A 32 × 16 image (2 × 2 tiles) whose pixel (row, col) looks at the screen
    /// point (col, 15 − row, 0), seen from (15.5, 7.5, 10): above the corner the
    /// four tiles share, so the planes between tiles are x = 15.5 (half a pixel
    /// right of column 15) and y = 7.5 (half a pixel below row 7).
    fn camera() -> Camera {
        Camera {
            position: Vec3::new(15.5, 7.5, 10.0),
            screen: Screen {
                left: 0.0,
                right: 31.0,
                top: 15.0,
                bottom: 0.0,
            },
            width: 32,
            height: 16,
        }
    }

    /// A sphere of radius 0.3 on the screen, centred where pixel (`row`, `col`)
    /// looks.
    fn on_screen(row: f64, col: f64) -> Object {
        ball(col, 15.0 - row, 0.0, 0.3)
    }

    /// The four spheres of the tests: in the top-left tile; 0.7 to the right of
    /// the planes between the top tiles (0.4 clear of it); 0.7 below the plane
    /// between the left tiles; on the corner of all four tiles.
    fn spheres() -> Vec<Object> {
        vec![
            on_screen(3.0, 4.0),
            on_screen(3.0, 16.2),
            on_screen(8.2, 4.0),
            on_screen(7.5, 15.5),
        ]
    }

    #[test]
    fn a_tile_lists_the_spheres_in_its_pyramid_and_no_other() {
        let masks = TileMasks::new(&camera(), &spheres());
        // Pixels at the corners of each tile, with the mask of its tile: the
        // sphere inside it and the one on the shared corner.
        for (pixels, mask) in [
            ([(0, 0), (7, 15)], 0b1001),
            ([(0, 16), (7, 31)], 0b1010),
            ([(8, 0), (15, 15)], 0b1100),
            ([(8, 16), (15, 31)], 0b1000),
        ] {
            for (row, col) in pixels {
                assert_eq!(masks.mask(row, col), mask, "pixel ({row}, {col})");
            }
        }
    }

    #[test]
    fn a_scene_of_64_objects_has_masks_and_one_of_65_has_none() {
        // The three spheres of one tile each, then the corner sphere until there
        // are 64: the top-right tile still leaves out objects 0 and 2.
        let mut objects = spheres();
        objects.resize(64, on_screen(7.5, 15.5));
        let masks = TileMasks::new(&camera(), &objects);
        assert_eq!(masks.mask(0, 16), EVERY & !0b101);
        // More objects than a mask has bits: every object, everywhere.
        objects.push(on_screen(7.5, 15.5));
        let masks = TileMasks::new(&camera(), &objects);
        assert_eq!(masks.mask(0, 16), EVERY);
    }
}
