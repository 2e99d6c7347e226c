//! The packet walk of the BVH: four rays walk the book's tree together, testing
//! its boxes in float32 where that is safe (`Bvh::enter_packet`), and ask a
//! [`PacketSearch`] to test the objects of the leaves they enter. It finds, lane
//! by lane, what the book's one-ray walk ([`Bvh::nearest_hit`]) finds.

use crate::bvh::{Bvh, Node, MARGIN};
use crate::fast::lanes::{convert, F32s, F64s, Laned, Lanes, ALL, V3};

/// What a search for objects along a packet's rays asks of them: the tree's walk
/// ([`Bvh::search_packet`]), or the plain loop.
pub trait PacketSearch {
    /// The lanes still searching (none: the search stops).
    fn active(&self) -> u32;
    /// For each lane, the distance beyond which a box need not be entered.
    fn limits(&self) -> F64s;
    /// Test object `index` against the rays.
    fn test(&mut self, index: usize);
    /// Test object `index`, a sphere of centre `ball[0..3]` and radius `ball[3]`.
    fn test_sphere(&mut self, index: usize, ball: &[f64; 4]);
}

impl Bvh {
    /// [`Bvh::enter`] for four rays at once, in precision `L`: where each enters
    /// the box of `node`, widened by its margin, and the lanes that enter it
    /// before their limit. `to_min` and `to_max` are the origins shifted by each
    /// lane's margin `m`, by `+m` for the low faces and by `−m` for the high ones,
    /// which widens the box by `m` on every side ([`Bvh::margin`]).
    ///
    /// In float32 the origin, the direction, its reciprocal and each step of the
    /// slab test round, and a box might seem missed by a ray that grazes it. The
    /// stored boxes reach `32·u·R` past the float64 ones (u = 2⁻²⁴ is float32's
    /// unit roundoff, R is [`Bvh::fast_reach`]), and [`Bvh::search_packet`] takes
    /// this path only for rays whose origin coordinates are at most R in size.
    /// Rounding the origin moves it by at most `u·R`; the slab value
    /// `(b − o)·(1/d)` then comes out within four roundings of the exact one, an
    /// error of at most `4u·|b − o| ≤ 4u·1.5R` along the axis (faces lie within
    /// R/2). Both together are less than the `32u·R` the faces were moved out, so
    /// a lane that enters the exact box also enters the stored one, at a smaller
    /// `t`, and its limit is rounded up ([`up_to_f32`]). (Scene files keep every
    /// coordinate within 10¹⁵, far inside float32's range, and R above its
    /// subnormals, or the tree is walked in float64.) The unit test
    /// `a_float32_box_test_enters_every_box_the_exact_ray_enters` fails with
    /// faces moved out by `2u·R`.
    ///
    /// The minima and maxima need not care for NaNs: one comes only from `0·∞`,
    /// an origin exactly on a stored face with the direction parallel to it, and
    /// such a ray passes `32u·R` outside the exact box, which any answer skips
    /// rightly or visits in vain.
    // ANCHOR: enter_packet
    #[inline(always)]
    fn enter_packet<L: Laned>(
        node: &Node,
        [to_min, to_max]: &[V3<L>; 2],
        inverse: &V3<L>,
        limit: L::Lanes,
    ) -> (L::Lanes, u32) {
        let slab = |min: f32, max: f32, lo: L::Lanes, hi: L::Lanes, inv: L::Lanes| {
            let face = |b: f32| L::Lanes::splat(L::of(f64::from(b)));
            let t1 = (face(min) - lo) * inv;
            let t2 = (face(max) - hi) * inv;
            (t1.fast_min(t2), t1.fast_max(t2))
        };
        let (nx, fx) = slab(node.min.x, node.max.x, to_min.x, to_max.x, inverse.x);
        let (ny, fy) = slab(node.min.y, node.max.y, to_min.y, to_max.y, inverse.y);
        let (nz, fz) = slab(node.min.z, node.max.z, to_min.z, to_max.z, inverse.z);
        let near = nx
            .fast_max(ny)
            .fast_max(nz)
            .fast_max(L::Lanes::splat(L::of(0.0)));
        let far = fx.fast_min(fy).fast_min(fz);
        (near, (far.ge(near) & limit.ge(near)).bits())
    }
    // ANCHOR_END: enter_packet

    // ANCHOR: search_packet
    /// Walk the tree with four rays from `origin` along `direction`: every object
    /// outside the tree, then every object of every leaf whose box some lane still
    /// searching enters before its limit. A lane's result is the one-ray walk's,
    /// because a lane skips only boxes that cannot hold a hit as near as its
    /// limit; objects it did not need are tested too, and cannot come nearer. The
    /// boxes are tested in float32 when every origin, moved by its margin, lies
    /// within `Bvh::fast_reach` (see `Bvh::enter_packet`), in float64 otherwise.
    #[inline(always)]
    pub fn search_packet<T: Laned, S: PacketSearch>(
        &self,
        origin: &V3<T>,
        direction: &V3<T>,
        search: &mut S,
    ) {
        for &i in &self.loose {
            search.test(i as usize);
        }
        if self.nodes.is_empty() {
            return;
        }
        // Each lane's margin (`Bvh::margin`), in float64.
        let o = origin.convert::<f64>();
        let u = F64s::splat(MARGIN * T::UNIT_ROUNDOFF.to_f64());
        let margin = u * (o.max_abs() + F64s::splat(self.size));
        let margin = V3::new(margin, margin, margin);
        let moved = [o + margin, o - margin];
        let reach = F64s::splat(f64::from(self.fast_reach));
        let within = reach.ge(moved[0].max_abs()) & reach.ge(moved[1].max_abs());
        if within.bits() == ALL {
            let moved = moved.map(|o| o.convert::<f32>());
            self.walk(&moved, &direction.convert::<f32>(), search, up_to_f32);
        } else {
            self.walk(&moved, &direction.convert::<f64>(), search, |l| l);
        }
    }
    // ANCHOR_END: search_packet

    /// The walk of [`Bvh::search_packet`], testing boxes in precision `L`, with
    /// the search's limits converted by `limits_in`.
    #[inline(always)]
    fn walk<L: Laned, S: PacketSearch>(
        &self,
        origins: &[V3<L>; 2],
        direction: &V3<L>,
        search: &mut S,
        limits_in: impl Fn(F64s) -> L::Lanes,
    ) {
        let one = L::Lanes::splat(L::of(1.0));
        let d = direction;
        let inverse = &V3::new(one / d.x, one / d.y, one / d.z);
        // The lanes still searching and their limits change only when a leaf's
        // objects are tested.
        let limits = |search: &S| (search.active(), limits_in(search.limits()));
        let enters = |node: usize, (active, limit): (u32, L::Lanes)| {
            let (near, bits) = Self::enter_packet(&self.nodes[node], origins, inverse, limit);
            (near, bits & active)
        };
        let mut now = limits(search);
        if enters(0, now).1 == 0 {
            return;
        }
        let mut stack = [0u32; 64];
        let mut depth = 0;
        let mut node = 0usize;
        loop {
            let n = self.nodes[node];
            if n.count > 0 {
                let run = n.first as usize..(n.first + n.count) as usize;
                for (&i, ball) in self.items[run.clone()].iter().zip(&self.balls[run]) {
                    search.test_sphere(i as usize, ball);
                    if search.active() == 0 {
                        return; // no lane is searching any more (all blocked)
                    }
                }
                now = limits(search);
            } else {
                let (a, b) = (node + 1, n.first as usize);
                let (ta, ma) = enters(a, now);
                let (tb, mb) = enters(b, now);
                if ma != 0 && mb != 0 {
                    // Nearer first for the lowest lane that enters both (the
                    // first child first if no lane enters both).
                    let both = ma & mb;
                    let lane = both.trailing_zeros() as usize;
                    let a_first = both == 0 || ta.to_array()[lane] <= tb.to_array()[lane];
                    let (near, far) = if a_first { (a, b) } else { (b, a) };
                    stack[depth] = far as u32;
                    depth += 1;
                    node = near;
                    continue;
                }
                if ma != 0 || mb != 0 {
                    node = if ma != 0 { a } else { b };
                    continue;
                }
            }
            // Next from the stack, skipping boxes no lane still needs.
            loop {
                if depth == 0 {
                    return;
                }
                depth -= 1;
                let candidate = stack[depth] as usize;
                if enters(candidate, now).1 != 0 {
                    node = candidate;
                    break;
                }
            }
        }
    }
}

/// Distances in float32, each at least the float64 one: rounded to nearest, then
/// multiplied by 1 + 2⁻²³, which lifts a normal float32 `r` to at least the next
/// one up (`r·2⁻²³` is at least its spacing), so `x` below `r`'s upper neighbour
/// is covered; the smallest subnormal added does the same for subnormals, which
/// the product does not lift. Infinity stays infinite.
fn up_to_f32(l: F64s) -> F32s {
    let up = F32s::splat(1.0 + f32::EPSILON);
    let tiny = F32s::splat(f32::from_bits(1));
    convert::<f64, f32>(l) * up + tiny
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_ball as ball;
    use crate::fast::lanes::WIDTH;
    use crate::Vec3;

    #[test]
    fn limits_never_shrink_in_float32() {
        // A limit never shrinks in float32, subnormals and the largest included.
        let limits = [
            1.4 * 2f64.powi(-149),
            1e-40,
            0.1,
            1.0 + 1e-12,
            3e38,
            f64::INFINITY,
        ];
        for chunk in limits.chunks(WIDTH) {
            let mut lanes = [0.0; WIDTH];
            lanes[..chunk.len()].copy_from_slice(chunk);
            let up = up_to_f32(F64s::from_array(lanes)).to_array();
            for (x, r) in lanes.iter().zip(up) {
                assert!(f64::from(r) >= *x, "{x} became {r}");
            }
        }
    }

    /// The float64 slab test of [`Bvh::enter`] on the box `min`..`max`, where it
    /// enters. A ray parallel to a slab (a direction component of zero) lies in
    /// it, faces included, along its whole length, or never: taken apart, not
    /// as `0·∞`, which is NaN for an origin on a face.
    fn enters_exact(min: Vec3, max: Vec3, origin: Vec3, direction: Vec3) -> Option<f64> {
        let (mut near, mut far) = (0.0f64, f64::INFINITY);
        for a in 0..3 {
            if direction[a] == 0.0 {
                if origin[a] < min[a] || origin[a] > max[a] {
                    return None;
                }
                continue;
            }
            let (t1, t2) = (
                (min[a] - origin[a]) / direction[a],
                (max[a] - origin[a]) / direction[a],
            );
            near = near.max(t1.min(t2));
            far = far.min(t1.max(t2));
        }
        (near <= far).then_some(near)
    }

    /// What the walk asks of a search, written down: the objects it is given to
    /// test, in order. Every lane searches until `stop_after_first` ends the
    /// search at the first object (as a shadow search ends once every lane is
    /// blocked); every lane's limit is `limit`, which becomes `limit_after_first`
    /// once an object has been tested (as a nearest search's limit shrinks to its
    /// first hit).
    struct Log {
        tested: Vec<usize>,
        limit: f64,
        limit_after_first: f64,
        stop_after_first: bool,
    }

    impl Log {
        fn new(limit: f64, limit_after_first: f64, stop_after_first: bool) -> Log {
            Log {
                tested: Vec::new(),
                limit,
                limit_after_first,
                stop_after_first,
            }
        }
    }

    impl PacketSearch for Log {
        fn active(&self) -> u32 {
            match self.stop_after_first && !self.tested.is_empty() {
                true => 0,
                false => ALL,
            }
        }
        fn limits(&self) -> F64s {
            F64s::splat(self.limit)
        }
        fn test(&mut self, index: usize) {
            self.tested.push(index);
            self.limit = self.limit_after_first;
        }
        fn test_sphere(&mut self, index: usize, _ball: &[f64; 4]) {
            self.test(index);
        }
    }

    /// Two groups of four spheres (radius 0.4, a leaf each: `LEAF` is 4), around
    /// x = −10 (objects 0 to 3) and x = +10 (objects 4 to 7), and the objects the
    /// walk gives `search` for four rays from (`x`, 0, 0) along (`dx`, 0, 0).
    fn walk_two_groups(x: f64, dx: f64, search: &mut Log) {
        let mut objects = Vec::new();
        for centre in [-10.0, 10.0] {
            for (y, z) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                objects.push(ball(centre, y, z, 0.4));
            }
        }
        let bvh = Bvh::build(&objects);
        assert_eq!(crate::bvh::LEAF, 4, "one leaf per group");
        let origin = V3::<f64>::splat(Vec3::new(x, 0.0, 0.0));
        let direction = V3::<f64>::splat(Vec3::new(dx, 0.0, 0.0));
        bvh.search_packet(&origin, &direction, search);
    }

    /// The objects of the group around `centre` (−10 or +10).
    fn group(centre: f64) -> Vec<usize> {
        if centre < 0.0 {
            vec![0, 1, 2, 3]
        } else {
            vec![4, 5, 6, 7]
        }
    }

    fn sorted(mut v: Vec<usize>) -> Vec<usize> {
        v.sort_unstable();
        v
    }

    // From ±15 the origins lie within the tree's fast reach (twice the largest
    // coordinate, 10.4) and the boxes are tested in float32; from ±100 in float64.
    const FROM: [f64; 2] = [15.0, 100.0];

    #[test]
    fn the_walk_enters_the_nearer_child_first() {
        // Rays along the x axis meet the group on their side first: its leaf is
        // walked first, the other after it, and every object once.
        for d in FROM {
            for side in [-1.0, 1.0] {
                let mut log = Log::new(f64::INFINITY, f64::INFINITY, false);
                walk_two_groups(side * d, -side, &mut log);
                let (near, far) = (group(side), group(-side));
                assert_eq!(sorted(log.tested[..4].to_vec()), near, "from {}", side * d);
                assert_eq!(sorted(log.tested[4..].to_vec()), far, "from {}", side * d);
            }
        }
    }

    #[test]
    fn a_box_beyond_every_lanes_limit_is_not_entered() {
        // From −d the near group's boxes lie at t from d − 10.4 to d − 9.6, the far
        // group's from d + 9.6: once the first object sets every limit to d, the
        // far leaf (left on the stack when the walk chose the near one) is skipped.
        for d in FROM {
            let mut log = Log::new(f64::INFINITY, d, false);
            walk_two_groups(-d, 1.0, &mut log);
            assert_eq!(sorted(log.tested), group(-1.0), "from {}", -d);
        }
    }

    #[test]
    fn a_box_behind_the_origin_is_not_entered() {
        // From the origin along +x the group around x = −10 is behind every ray.
        for dx in [1.0, -1.0] {
            let mut log = Log::new(f64::INFINITY, f64::INFINITY, false);
            walk_two_groups(0.0, dx, &mut log);
            assert_eq!(sorted(log.tested), group(dx), "along {dx}");
        }
    }

    #[test]
    fn the_walk_stops_once_no_lane_is_searching() {
        // A shadow search ends when every lane is blocked: the first object tested
        // blocks them all here, and the walk asks for no other, in its leaf or out.
        for d in FROM {
            let mut log = Log::new(f64::INFINITY, f64::INFINITY, true);
            walk_two_groups(-d, 1.0, &mut log);
            assert_eq!(log.tested.len(), 1, "from {}: {:?}", -d, log.tested);
        }
    }

    proptest::proptest! {
        #![proptest_config({
            let cases: u32 = std::env::var("RAYSTEP_PROPTEST_CASES")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(4000);
            // Rays that float64 rounds out of the box are rejected: about 6 % of
            // the cases (2 % of those along a face). A quarter fails the test.
            proptest::prelude::ProptestConfig {
                max_global_rejects: cases / 4,
                ..proptest::prelude::ProptestConfig::with_cases(cases)
            }
        })]

        /// The float32 box test of the packet walk never skips a sphere's box that
        /// the float64 test enters, for rays that graze the box's faces, edges and
        /// corners (some along a face, with a direction component of zero), from
        /// anywhere within the fast reach, at scales from 10⁻¹⁰ to 10¹⁴; nor does the
        /// packet walk's float64 test of the stored boxes.
        #[test]
        fn a_float32_box_test_enters_every_box_the_exact_ray_enters(
            scale in -10.0f64..14.0,
            far in 0.0f64..1.0,
            centre in proptest::array::uniform3(-1.0f64..1.0),
            size in 0.001f64..1.0,
            from in proptest::array::uniform3(-1.0f64..1.0),
            on in proptest::array::uniform3(0.0f64..1.0),
            face in 0usize..6,
            bounds in 1usize..=3,
            parallel in proptest::bool::ANY,
        ) {
            let s = 10f64.powf(scale);
            let c = Vec3::from(centre) * s * 10f64.powf(far);
            let r = s * size;
            let objects = [ball(c.x, c.y, c.z, r)];
            let bvh = Bvh::build(&objects);
            // A point on the sphere's tight box: on a face, an edge or a corner.
            let (min, max) = (c - r, c + r);
            let mut p = min + (max - min) * Vec3::from(on);
            let axis = face % 3;
            for k in 0..bounds {
                let a = (axis + k) % 3;
                p[a] = if (face + k) % 2 == 0 { min[a] } else { max[a] };
            }
            let mut origin = Vec3::from(from) * f64::from(bvh.fast_reach);
            if parallel {
                // Along the face: a direction component of exactly zero.
                origin[axis] = p[axis];
            }
            let direction = (p - origin).normalize();
            proptest::prop_assume!(direction.is_finite());
            // A ray rounded out of the box in float64 has nothing to check; too
            // many such cases fail the test (proptest's limit of rejects).
            let t = enters_exact(min, max, origin, direction);
            proptest::prop_assume!(t.is_some(), "rounded out of the box in float64");
            let t = t.unwrap();
            let lanes = |v: Vec3| V3::<f64>::splat(v).convert::<f32>();
            // As the walk makes them: the reciprocal of the float32 direction.
            let (o, d) = (lanes(origin), lanes(direction));
            let one = F32s::splat(1.0);
            let inverse = V3::new(one / d.x, one / d.y, one / d.z);
            // The tightest limit: the exact ray's own entry distance.
            let limit = up_to_f32(F64s::splat(t));
            let (near, bits) = Bvh::enter_packet(&bvh.nodes[0], &[o, o], &inverse, limit);
            proptest::prop_assert_eq!(bits, ALL, "t = {}", t);
            proptest::prop_assert!(f64::from(near.to_array()[0]) <= t);
            // The float64 lanes, which rays from farther away take, too.
            let wide = |v: Vec3| V3::<f64>::splat(v);
            let (o, inverse) = (wide(origin), wide(Vec3::ONE / direction));
            let (near, bits) = Bvh::enter_packet(&bvh.nodes[0], &[o, o], &inverse, F64s::splat(t));
            proptest::prop_assert_eq!(bits, ALL, "t = {}", t);
            proptest::prop_assert!(near.to_array()[0] <= t);
        }
    }
}
