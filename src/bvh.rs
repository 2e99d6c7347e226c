//! A bounding volume hierarchy: boxes around groups of spheres, boxes around
//! groups of boxes, so that a ray tests only the spheres whose boxes it crosses.
//!
//! **Build.** Every sphere gets its axis-aligned box. A node's spheres are
//! sorted by their box centres into `BINS` bins (fewer near the leaves) along the
//! axis where the centres spread most and split
//! between the two bins where the surface area heuristic is least: the sum over
//! both sides of the side's box area (how likely a ray that crosses the node is to
//! cross it) times its number of spheres. Each side is split again, until at most
//! [`LEAF`] spheres remain. The binned heuristic builds in O(n log n), makes
//! better trees than a split at the median where spheres cluster, and never an
//! empty child; from depth `SAH_DEPTH` on the median takes over, which keeps
//! the depth below 64, so a fixed traversal stack always suffices. Subtrees of
//! `PARALLEL_FROM` spheres or more are built on rayon's threads into lists of
//! their own, joined in a fixed order: the tree depends on the spheres alone, not
//! on the thread count. The spheres are partitioned in place in one list, so each
//! leaf's spheres are a slice of it and no node allocates.
//!
//! **Traversal.** A ray enters the root's box; at a node it visits the nearer child
//! first and skips any box it enters beyond the nearest hit found so far. The
//! `[[plane]]` entries (true planes, the tutorial's huge floor sphere) stay
//! outside the tree and are tested for every ray.
//!
//! The result is the plain loop's: the same object at the same distance, ties
//! going to the lower index as the plain loop's strict `<` gives them (a test
//! renders both ways and compares the bytes). Boxes are computed in float64,
//! widened by a relative 1e-9, far more than their rounding, rounded outwards to
//! float32, joined, then widened once more and kept in float32, rounded outwards ([`Bvh::build`]): the one-ray walk
//! tests them in float64, and four rays test them in float32, half the work of
//! float64 lanes, unless a ray starts too far out (`Bvh::enter_packet`, in
//! `src/fast/walk.rs`). A node is
//! 32 bytes, two to a cache line.
//!
//! **Rounding of the sphere test.** In the precision the render computes in, the
//! intersection test can report a hit for a ray that passes a little outside a
//! sphere, by up to a few roundings of the numbers it subtracts: the ray's origin
//! and the sphere's centre. So each ray tests the boxes widened by a margin of
//! [`MARGIN`]`·u·(|O| + S)`, with `|O|` its origin's largest coordinate and `S` the
//! largest coordinate of any sphere's box ([`Bvh::margin`]). The margin is the
//! ray's own: a scene's far-away floor, whose size has nothing to do with the
//! numbers a ray and a small sphere are tested with, does not widen every box.

use crate::ray::Ray;
use crate::real::{Real, Vector};
use crate::scene::{consider, Hit, Object, Role, Shape};
use crate::sphere::Method;
use crate::Vec3;
use rayon::prelude::*;

/// Most spheres in a leaf.
pub const LEAF: usize = 4;

/// One node: a box (in float32, rounded outwards), and either two children or a
/// run of objects. 32 bytes, aligned so that a node never straddles two cache
/// lines.
#[derive(Clone, Copy, Debug)]
#[repr(align(32))]
pub(crate) struct Node {
    pub(crate) min: glam::Vec3,
    pub(crate) max: glam::Vec3,
    /// Leaf: the first of its objects in `items`. Inner node: its second child
    /// (the first is the next node).
    pub(crate) first: u32,
    /// Leaf: how many objects; inner node: 0.
    pub(crate) count: u32,
}

/// The hierarchy over a scene's spheres.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub(crate) nodes: Vec<Node>,
    /// Object indices, leaf by leaf.
    pub(crate) items: Vec<u32>,
    /// The centre and radius of each sphere of `items`, in the same order, so
    /// that a leaf's spheres sit side by side in memory (for packets).
    pub(crate) balls: Vec<[f64; 4]>,
    /// Objects outside the tree, tested for every ray.
    pub(crate) loose: Vec<u32>,
    /// Rays whose origin has no coordinate larger than this (in size) may test
    /// the boxes in float32: twice the largest coordinate of the root box (rounded
    /// down to float32).
    pub(crate) fast_reach: f32,
    /// The largest coordinate of any sphere's box (`S` of [`Bvh::margin`]).
    pub(crate) size: f64,
}

/// How far outside a sphere its intersection test may report a hit, in units of
/// `u·(|O| + S)` (see [`Bvh::margin`]).
///
/// The bound, as [`crate::shade::shadow::sphere_step`]'s is derived (Higham's
/// model, `|δ| ≤ u` per operation, first order in `u`), for the stable test's
/// `Δ/4 = r² − ‖h·d − m‖²` (the naive method builds no tree):
///
/// 1. `m = C − O` is rounded per component: `u·‖m‖`;
/// 2. `h = ⟨d, m⟩` is off by `γ_3·‖m‖`, and `h·d − m` rounds its product and
///    its difference: with 1., the closest-point vector is within `8u·‖m‖` of
///    the exact one (the direction's length, `1 ± 4u`, moves it along `d`
///    only, which is of second order in its length);
/// 3. `‖h·d − m‖²` (`γ_3`) and `r²` (`u`) move the distance compared with `r`
///    by `1.5u·r` and `0.5u·r`.
///
/// So a reported hit passes within `r + u·(8·‖m‖ + 2r)` of the centre, and with
/// `‖m‖ ≤ √3·(|O| + S)` and `r ≤ S` that is within `(8√3 + 2)·u·(|O| + S)`,
/// about `16u·(|O| + S)`, of the sphere's box. The same margin moves every box's
/// entry at least that much closer along the ray, which covers the error of the
/// hit's distance (`c/q`: about `4u·‖m‖`) when a box is skipped for a nearer
/// hit. The boxes' own rounding is apart: computed in float64 and rounded
/// outwards, and padded for the packets' float32 test (`FAST_PAD`).
///
/// 64 is four times that first-order 16, kept as it was: the factor covers the
/// second-order terms with room to spare, a wider box changes no pixel, and
/// the width it adds (64u of `|O| + S`: 7.1e-15 of it in float64, 3.8e-6
/// in float32) is far below the boxes' own; too narrow a margin would change
/// pixels (the fast engine's bit-identity test, `tests/speed.rs`, renders every
/// scene both ways).
pub const MARGIN: f64 = 64.0;

/// A ray as the slab test sees it: its origin shifted by the ray's margin `m`, by
/// `+m` for the low faces (`to_min`: `min − (O + m)` is `(min − m) − O`) and by
/// `−m` for the high ones (`to_max`), so that the test is of the box widened by
/// the margin on every side; and the reciprocal of its direction.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slabs {
    to_min: Vec3,
    to_max: Vec3,
    inverse: Vec3,
}

/// How much farther than their float64 boxes the stored boxes reach, in units of
/// float32's unit roundoff times [`Bvh::fast_reach`]: enough that a float32 box
/// test of a ray from within that reach never misses a box the exact ray enters
/// (see `Bvh::enter_packet`, in `src/fast/walk.rs`).
const FAST_PAD: f64 = 32.0;

/// A sphere while the tree is built: its box (the float64 box rounded outwards
/// to float32, in SIMD registers: one instruction takes the minimum of two
/// corners) and its object index.
#[derive(Clone, Copy)]
struct Item {
    min: glam::Vec3A,
    max: glam::Vec3A,
    index: u32,
    /// The bin [`divide`] put it in last (kept in what would be padding, so
    /// that the partition after the binning need not compute it again).
    bin: u32,
}

impl Item {
    /// The centre of the box, by which spheres are sorted into bins.
    #[inline]
    fn centre(&self) -> glam::Vec3A {
        (self.min + self.max) * 0.5
    }
}

/// Bins of the surface area heuristic ([`divide`]).
const BINS: usize = 16;

/// Nodes of at most this many spheres are split over [`FEW_BINS`] bins: near the
/// leaves a split has few places to go, and setting up and sweeping sixteen bins
/// would cost more than sorting the spheres into them.
const FEW_FROM: usize = 32;

/// Bins of the surface area heuristic for nodes of at most [`FEW_FROM`] spheres.
const FEW_BINS: usize = 8;

/// From this depth on, a node is split at the median, whatever the surface area
/// heuristic would choose: the median keeps the rest of the tree within
/// log₂(n / [`LEAF`]) + 1 < 32 more levels for any n below 2³², so that no walk
/// of the tree needs more than the 64 entries of its fixed stack.
const SAH_DEPTH: usize = 32;

/// Subtrees of at least this many spheres are built on rayon's threads (their two
/// children in parallel, each into a list of its own, joined in order); smaller
/// ones on the thread that reached them. The tree is the same either way.
const PARALLEL_FROM: usize = 8192;

/// Which of `N` bins the centre coordinate `c` falls in.
#[inline]
fn bin_of<const N: usize>(c: f32, low: f32, scale: f32) -> usize {
    (((c - low) * scale) as usize).min(N - 1)
}

/// A box, growing as spheres are added.
#[derive(Clone, Copy)]
struct Bounds {
    min: glam::Vec3A,
    max: glam::Vec3A,
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        min: glam::Vec3A::INFINITY,
        max: glam::Vec3A::NEG_INFINITY,
    };

    #[inline]
    fn add(&mut self, min: glam::Vec3A, max: glam::Vec3A) {
        (self.min, self.max) = (self.min.min(min), self.max.max(max));
    }

    #[inline]
    fn join(&mut self, other: &Bounds) {
        self.add(other.min, other.max);
    }

    /// Half the surface area (0 for an empty box).
    #[inline]
    fn half_area(&self) -> f64 {
        let d = (self.max - self.min).max(glam::Vec3A::ZERO).as_dvec3();
        d.x * d.y + d.y * d.z + d.z * d.x
    }

    /// The node of this box widened by `widen` (rounded outwards to float32).
    fn node(&self, widen: f64, first: u32, count: u32) -> Node {
        let (min, max) = (self.min.as_dvec3() - widen, self.max.as_dvec3() + widen);
        Node {
            min: min.to_array().map(below).into(),
            max: max.to_array().map(above).into(),
            first,
            count,
        }
    }
}

impl Bvh {
    /// Build the hierarchy over the `[[sphere]]` objects of `objects`, each box
    /// widened by what the packet walk's float32 test needs (`FAST_PAD`). The
    /// rounding of the intersection test in precision `T` is each ray's margin
    /// ([`Bvh::margin`]), added when the ray tests a box. (The textbook
    /// quadratic's rounding can report hits far outside a sphere; a box would hide
    /// them and change the picture, so the tracer uses no BVH with `--intersect
    /// naive`.)
    ///
    /// The tree depends only on the objects: built on one thread or many, it is
    /// the same, node for node.
    pub fn build<T: Real>(objects: &[Object<T>]) -> Bvh {
        let mut items = Vec::with_capacity(objects.len());
        let mut loose = Vec::new();
        let mut largest = 0.0f64;
        for (i, o) in objects.iter().enumerate() {
            match o.shape {
                Shape::Sphere(s) if o.role == Role::Sphere => {
                    let (c, r) = (s.center.to_f64(), s.radius.to_f64());
                    let half = Vec3::splat(r + 1e-9 * (r + c.abs().max_element()));
                    let (min, max) = (c - half, c + half);
                    largest = largest
                        .max(min.abs().max_element())
                        .max(max.abs().max_element());
                    items.push(Item {
                        min: min.to_array().map(below).into(),
                        max: max.to_array().map(above).into(),
                        index: i as u32,
                        bin: 0,
                    });
                }
                _ => loose.push(i as u32),
            }
        }
        let reach = 2.0 * largest;
        // Below float32's normal numbers the rounding of an origin is not relative
        // (and the bound of `Bvh::enter_packet`, in src/fast/walk.rs, fails): such a tree is walked in float64.
        let fast_reach = if largest < 1e-30 { -1.0 } else { below(reach) };
        let widen = FAST_PAD * f64::from(f32::EPSILON / 2.0) * reach;
        let nodes = if items.is_empty() {
            Vec::new()
        } else {
            let span = Span::of(&items);
            subtree(&mut items, span, 0, 0, widen)
        };
        // The leaves' spheres in the order of the tree: each leaf's run of `items`
        // is its slice of the partitioned list.
        Bvh {
            nodes,
            items: items.par_iter().map(|i| i.index).collect(),
            balls: items
                .par_iter()
                .map(|i| match objects[i.index as usize].shape {
                    Shape::Sphere(s) => {
                        let c = s.center.to_f64();
                        [c.x, c.y, c.z, s.radius.to_f64()]
                    }
                    Shape::Plane(_) => unreachable!("only spheres are in the tree"),
                })
                .collect(),
            loose,
            fast_reach,
            size: largest,
        }
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes the hierarchy holds.
    pub fn bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + (self.items.capacity() + self.loose.capacity()) * 4
            + self.balls.capacity() * std::mem::size_of::<[f64; 4]>()
    }

    /// How much wider than its spheres' boxes a ray from `origin` must see them,
    /// computing in a precision of unit roundoff `u`: [`MARGIN`]`·u·(|O| + S)`,
    /// with `|O|` the origin's largest coordinate and `S` the largest of any box.
    /// (The numbers a sphere test subtracts are at most that large.)
    #[inline]
    pub fn margin(&self, u: f64, origin: Vec3) -> f64 {
        MARGIN * u * (origin.abs().max_element() + self.size)
    }

    /// `ray` as the slab test sees it, computing in precision `T`.
    #[inline]
    fn slabs<T: Real>(&self, ray: &Ray<T>) -> Slabs {
        let origin = ray.origin.to_f64();
        let margin = Vec3::splat(self.margin(T::UNIT_ROUNDOFF.to_f64(), origin));
        Slabs {
            to_min: origin + margin,
            to_max: origin - margin,
            inverse: Vec3::ONE / ray.direction.to_f64(),
        }
    }

    // ANCHOR: enter
    /// Where a ray enters the box of `node`, widened by its margin, if it does
    /// before `limit`.
    #[inline]
    fn enter(node: &Node, ray: &Slabs, limit: f64) -> Option<f64> {
        let t1 = (node.min.as_dvec3() - ray.to_min) * ray.inverse;
        let t2 = (node.max.as_dvec3() - ray.to_max) * ray.inverse;
        // A direction component of 0 makes that axis's slab ±∞ (the ray is inside
        // the slab for ever, or never); `f64::min` and `max` skip the NaN of
        // 0 · ∞, a ray exactly in a face plane.
        let near =
            t1.x.min(t2.x)
                .max(t1.y.min(t2.y))
                .max(t1.z.min(t2.z))
                .max(0.0);
        let far = t1.x.max(t2.x).min(t1.y.max(t2.y)).min(t1.z.max(t2.z));
        (near <= far && near <= limit).then_some(near)
    }
    // ANCHOR_END: enter

    /// The nearest object along `ray`, as [`crate::scene::nearest_hit`] finds it.
    pub fn nearest_hit<T: Real>(
        &self,
        objects: &[Object<T>],
        ray: &Ray<T>,
        method: Method,
    ) -> Option<Hit<T>> {
        let mut nearest: Option<Hit<T>> = None;
        for &i in &self.loose {
            consider(objects, ray, method, i as usize, &mut nearest);
        }
        if self.nodes.is_empty() {
            return nearest;
        }
        let slabs = &self.slabs(ray);
        let mut stack = [0u32; 64];
        let mut depth = 0;
        let mut node = 0usize;
        let limit = |n: &Option<Hit<T>>| n.map_or(f64::INFINITY, |h| h.t.to_f64());
        if Self::enter(&self.nodes[0], slabs, f64::INFINITY).is_none() {
            return nearest;
        }
        loop {
            let n = self.nodes[node];
            if n.count > 0 {
                for k in n.first..n.first + n.count {
                    consider(
                        objects,
                        ray,
                        method,
                        self.items[k as usize] as usize,
                        &mut nearest,
                    );
                }
            } else {
                // ANCHOR: descend
                let bound = limit(&nearest);
                let (a, b) = (node + 1, n.first as usize);
                let ta = Self::enter(&self.nodes[a], slabs, bound);
                let tb = Self::enter(&self.nodes[b], slabs, bound);
                match (ta, tb) {
                    (Some(ta), Some(tb)) => {
                        let (near, far) = if ta <= tb { (a, b) } else { (b, a) };
                        stack[depth] = far as u32;
                        depth += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = a;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = b;
                        continue;
                    }
                    (None, None) => {}
                }
                // ANCHOR_END: descend
            }
            // Next from the stack, skipping boxes now beyond the nearest hit.
            loop {
                if depth == 0 {
                    return nearest;
                }
                depth -= 1;
                let candidate = stack[depth] as usize;
                let bound = limit(&nearest);
                if Self::enter(&self.nodes[candidate], slabs, bound).is_some() {
                    node = candidate;
                    break;
                }
            }
        }
    }

    /// Is any object hit along `ray` closer than `distance`? As
    /// [`crate::scene::blocked`], stopping at the first blocker.
    pub fn blocked<T: Real>(
        &self,
        objects: &[Object<T>],
        ray: &Ray<T>,
        distance: T,
        method: Method,
    ) -> bool {
        let hits = |index: u32| {
            objects[index as usize]
                .intersect(ray, method)
                .is_some_and(|t| t < distance)
        };
        if self.loose.iter().any(|&i| hits(i)) {
            return true;
        }
        if self.nodes.is_empty() {
            return false;
        }
        let slabs = &self.slabs(ray);
        let bound = distance.to_f64();
        let mut stack = [0u32; 64];
        let mut depth = 0;
        if Self::enter(&self.nodes[0], slabs, bound).is_none() {
            return false;
        }
        let mut node = 0usize;
        loop {
            let n = self.nodes[node];
            if n.count > 0 {
                if (n.first..n.first + n.count).any(|k| hits(self.items[k as usize])) {
                    return true;
                }
            } else {
                let (a, b) = (node + 1, n.first as usize);
                let ta = Self::enter(&self.nodes[a], slabs, bound).is_some();
                let tb = Self::enter(&self.nodes[b], slabs, bound).is_some();
                if ta && tb {
                    stack[depth] = b as u32;
                    depth += 1;
                }
                if ta || tb {
                    node = if ta { a } else { b };
                    continue;
                }
            }
            if depth == 0 {
                return false;
            }
            depth -= 1;
            node = stack[depth] as usize;
        }
    }
}

/// The box of some spheres and the box of their centres.
#[derive(Clone, Copy)]
struct Span {
    bounds: Bounds,
    centres: Bounds,
}

impl Span {
    const EMPTY: Span = Span {
        bounds: Bounds::EMPTY,
        centres: Bounds::EMPTY,
    };

    #[inline]
    fn add(&mut self, item: &Item) {
        self.bounds.add(item.min, item.max);
        let c = item.centre();
        self.centres.add(c, c);
    }

    #[inline]
    fn join(&mut self, other: &Span) {
        self.bounds.join(&other.bounds);
        self.centres.join(&other.centres);
    }

    /// The span of `items`.
    fn of(items: &[Item]) -> Span {
        let mut span = Span::EMPTY;
        for i in items {
            span.add(i);
        }
        span
    }
}

/// The nodes of the subtree over `items` (of span `span`), the slice of the
/// build's list that starts at `offset`, at `depth` in the tree: depth first,
/// each node's first child right after it, its second child's index (`first`)
/// counted from the subtree's root. The two children of a large subtree are
/// built in parallel, each into a list of its own, and joined; a small one is
/// grown into one list ([`grow`]).
fn subtree(items: &mut [Item], span: Span, offset: usize, depth: usize, widen: f64) -> Vec<Node> {
    if items.len() < PARALLEL_FROM {
        let mut nodes = Vec::with_capacity(items.len());
        grow(items, span, offset, depth, widen, &mut nodes);
        return nodes;
    }
    let (middle, spans) = divide(items, &span, depth);
    let (left, right) = items.split_at_mut(middle);
    let (a, b) = rayon::join(
        || subtree(left, spans[0], offset, depth + 1, widen),
        || subtree(right, spans[1], offset + middle, depth + 1, widen),
    );
    let mut nodes = Vec::with_capacity(1 + a.len() + b.len());
    nodes.push(span.bounds.node(widen, (1 + a.len()) as u32, 0));
    for part in [a, b] {
        let base = nodes.len() as u32;
        nodes.extend(part.into_iter().map(|mut n| {
            if n.count == 0 {
                n.first += base;
            }
            n
        }));
    }
    nodes
}

/// Add the subtree over `items` (of span `span`, the slice of the build's list
/// from `offset`) to `nodes`, depth first.
fn grow(
    items: &mut [Item],
    span: Span,
    offset: usize,
    depth: usize,
    widen: f64,
    nodes: &mut Vec<Node>,
) {
    if items.len() <= LEAF {
        nodes.push(span.bounds.node(widen, offset as u32, items.len() as u32));
        return;
    }
    let (middle, spans) = divide(items, &span, depth);
    let at = nodes.len();
    nodes.push(span.bounds.node(widen, 0, 0));
    let (left, right) = items.split_at_mut(middle);
    grow(left, spans[0], offset, depth + 1, widen, nodes);
    nodes[at].first = nodes.len() as u32;
    grow(right, spans[1], offset + middle, depth + 1, widen, nodes);
}

/// Split `items` (of span `span`) in two, in place: the spheres of the first
/// child first. Returns how many those are (never 0 nor all) and the two
/// children's spans.
///
/// The split is by the surface area heuristic over [`BINS`] bins of the box
/// centres ([`FEW_BINS`] for nodes of at most [`FEW_FROM`] spheres) along the
/// axis where they spread most: the boundary between two bins
/// that minimises each side's box area times its number of spheres (the lowest
/// such). From depth [`SAH_DEPTH`] on, or where every centre is the same, it is
/// at the median along that axis instead.
fn divide(items: &mut [Item], span: &Span, depth: usize) -> (usize, [Span; 2]) {
    let spread = span.centres.max - span.centres.min;
    let axis = if spread.x >= spread.y && spread.x >= spread.z {
        0
    } else if spread.y >= spread.z {
        1
    } else {
        2
    };
    let scale = BINS as f32 / spread[axis];
    if depth >= SAH_DEPTH || !(spread[axis] > 0.0 && scale.is_finite()) {
        let middle = items.len() / 2;
        items.select_nth_unstable_by(middle, |a, b| {
            a.centre()[axis]
                .total_cmp(&b.centre()[axis])
                .then(a.index.cmp(&b.index))
        });
        let (left, right) = items.split_at(middle);
        return (middle, [Span::of(left), Span::of(right)]);
    }
    let low = span.centres.min[axis];
    if items.len() <= FEW_FROM {
        let scale = FEW_BINS as f32 / spread[axis];
        binned::<FEW_BINS>(items, axis, low, scale)
    } else {
        binned::<BINS>(items, axis, low, scale)
    }
}

/// The split of [`divide`] over `N` bins along `axis`, the first from `low` on,
/// `scale` of them to a unit of length.
#[inline(always)]
fn binned<const N: usize>(
    items: &mut [Item],
    axis: usize,
    low: f32,
    scale: f32,
) -> (usize, [Span; 2]) {
    let mut bins = [Span::EMPTY; N];
    let mut counts = [0u32; N];
    for i in items.iter_mut() {
        let k = bin_of::<N>(i.centre()[axis], low, scale);
        i.bin = k as u32;
        counts[k] += 1;
        bins[k].add(i);
    }
    // The area of the bins from k on, for each k.
    let mut right_area = [0.0; N];
    let mut right = Bounds::EMPTY;
    for k in (1..N).rev() {
        right.join(&bins[k].bounds);
        right_area[k] = right.half_area();
    }
    let mut best = (f64::INFINITY, 0);
    let mut left = Bounds::EMPTY;
    let mut on_left = 0usize;
    for k in 0..N - 1 {
        left.join(&bins[k].bounds);
        on_left += counts[k] as usize;
        let on_right = items.len() - on_left;
        if on_left == 0 || on_right == 0 {
            continue;
        }
        let cost = left.half_area() * on_left as f64 + right_area[k + 1] * on_right as f64;
        if cost < best.0 {
            best = (cost, k);
        }
    }
    // The lowest and the highest centre fall in the first and the last bin, so
    // some boundary has spheres on both sides.
    let bin = best.1;
    let mut spans = [Span::EMPTY; 2];
    for (k, b) in bins.iter().enumerate() {
        spans[usize::from(k > bin)].join(b);
    }
    let (mut i, mut j) = (0, items.len());
    while i < j {
        if items[i].bin as usize <= bin {
            i += 1;
        } else {
            j -= 1;
            items.swap(i, j);
        }
    }
    (i, spans)
}

/// The largest float32 not above `x`.
///
/// Whether `x` rounded to float32 comes out above or below it is as good as
/// random, so the step down is made whatever, and picked by a mask, not a
/// branch that the processor would mispredict half the time.
pub(crate) fn below(x: f64) -> f32 {
    let r = x as f32;
    // One step down (what `f32::next_down` does, from Rust 1.86 on): of the
    // bits, one less above zero and one more below it; from zero, to the
    // smallest negative subnormal (one more than the bits of -0).
    let s = if r == 0.0 { -0.0f32 } else { r }.to_bits() as i32;
    let down = s.wrapping_sub((s >> 31).wrapping_mul(2).wrapping_add(1)) as u32;
    let keep = u32::from(f64::from(r) <= x).wrapping_neg();
    f32::from_bits((r.to_bits() & keep) | (down & !keep))
}

/// The smallest float32 not below `x`.
pub(crate) fn above(x: f64) -> f32 {
    -below(-x)
}

/// A sphere of centre (`x`, `y`, `z`) and radius `r` (for the tests here and of
/// the packet walk).
#[cfg(test)]
pub(crate) fn test_ball(x: f64, y: f64, z: f64, r: f64) -> Object {
    Object {
        shape: Shape::Sphere(crate::sphere::Sphere {
            center: Vec3::new(x, y, z),
            radius: r,
        }),
        material: crate::scene::Material {
            ambient: Vec3::ZERO,
            diffuse: Vec3::ONE,
            specular: Vec3::ZERO,
            shininess: 100.0,
            reflection: 0.0,
        },
        role: Role::Sphere,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Object;

    use super::test_ball as ball;

    /// The depth of the subtree at `node`, checking on the way that each leaf
    /// holds 1 to `LEAF` spheres and each node's box holds its children's.
    fn depth(bvh: &Bvh, node: usize) -> usize {
        let n = bvh.nodes[node];
        let inside = |m: &Node| n.min.cmple(m.min).all() && m.max.cmple(n.max).all();
        if n.count > 0 {
            assert!(n.count as usize <= LEAF);
            for b in &bvh.balls[n.first as usize..(n.first + n.count) as usize] {
                let (c, r) = (Vec3::new(b[0], b[1], b[2]), b[3]);
                assert!(
                    n.min.as_dvec3().cmple(c - r).all() && (c + r).cmple(n.max.as_dvec3()).all()
                );
            }
            1
        } else {
            let (a, b) = (node + 1, n.first as usize);
            assert!(inside(&bvh.nodes[a]) && inside(&bvh.nodes[b]));
            1 + depth(bvh, a).max(depth(bvh, b))
        }
    }

    /// Walk the whole tree from the root and check that it reaches every node
    /// once and each of the `count` objects but those outside the tree once, in
    /// one leaf (a tree whose links
    /// were off would skip some and reach others twice, with every box still
    /// holding what it points to).
    fn reaches_each_node_and_sphere_once(bvh: &Bvh, count: usize) {
        let (mut stack, mut nodes, mut spheres) = (vec![0usize], 0, Vec::new());
        while let Some(i) = stack.pop() {
            nodes += 1;
            let n = bvh.nodes[i];
            if n.count > 0 {
                spheres
                    .extend_from_slice(&bvh.items[n.first as usize..(n.first + n.count) as usize]);
            } else {
                stack.extend([i + 1, n.first as usize]);
            }
        }
        assert_eq!(nodes, bvh.nodes.len(), "nodes reached from the root");
        // Every object that is not outside the tree, once.
        spheres.sort_unstable();
        let tree: Vec<u32> = (0..count as u32)
            .filter(|i| !bvh.loose.contains(i))
            .collect();
        assert!(
            spheres == tree,
            "{} spheres reached of {}",
            spheres.len(),
            tree.len()
        );
    }

    fn grid(count: i32) -> Vec<Object> {
        (0..count)
            .map(|i| {
                ball(
                    f64::from(i % 10),
                    f64::from(i / 100),
                    f64::from((i / 10) % 10),
                    0.3,
                )
            })
            .collect()
    }

    #[test]
    fn every_sphere_sits_in_one_leaf_and_the_depth_fits_the_stack() {
        let objects = grid(1000);
        let bvh = Bvh::build(&objects);
        reaches_each_node_and_sphere_once(&bvh, 1000);
        // The surface area heuristic keeps an even grid about balanced:
        // log2(1000 / LEAF) + 1 is 9 levels.
        assert!(depth(&bvh, 0) <= 12, "{}", depth(&bvh, 0));
        // Leaves' spheres in `balls` are theirs.
        for (k, &i) in bvh.items.iter().enumerate() {
            let Shape::Sphere(s) = objects[i as usize].shape else {
                unreachable!()
            };
            assert_eq!(bvh.balls[k], [s.center.x, s.center.y, s.center.z, s.radius]);
        }
    }

    #[test]
    fn uneven_scenes_keep_the_depth_within_the_stack() {
        // Spheres each 1.5 times as far out as the one before: the heuristic cuts
        // off one at a time, until the median takes over at SAH_DEPTH.
        let chain: Vec<Object> = (0..200)
            .map(|i| ball(1.5f64.powi(i), 0.0, 0.0, 0.1))
            .collect();
        // Many spheres at one centre: no split of the centres but the median's.
        let same: Vec<Object> = (0..5000).map(|_| ball(1.0, 2.0, 3.0, 0.5)).collect();
        for objects in [chain, same] {
            let bvh = Bvh::build(&objects);
            let d = depth(&bvh, 0);
            assert!(d < 64, "{d}");
            reaches_each_node_and_sphere_once(&bvh, objects.len());
        }
    }

    #[test]
    fn the_tree_is_the_same_on_one_thread_and_on_many() {
        // Large enough for the parallel build (PARALLEL_FROM), on pools of 1 and 3.
        let objects = crate::tools::generate::scene(3 * PARALLEL_FROM, 5).objects;
        let build = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| Bvh::build::<f64>(&objects))
        };
        let (one, three) = (build(1), build(3));
        depth(&one, 0);
        reaches_each_node_and_sphere_once(&one, objects.len());
        let bits = |b: &Bvh| {
            b.nodes
                .iter()
                .map(|n| {
                    (
                        n.min.to_array().map(f32::to_bits),
                        n.max.to_array().map(f32::to_bits),
                        n.first,
                        n.count,
                    )
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(bits(&one), bits(&three));
        assert_eq!(one.items, three.items);
        assert_eq!(one.loose, three.loose);
    }

    #[test]
    fn a_ray_down_a_row_of_spheres_hits_the_first() {
        let objects: Vec<Object> = (0..100)
            .map(|i| ball(0.0, 0.0, -f64::from(i) - 2.0, 0.4))
            .collect();
        let bvh = Bvh::build(&objects);
        let ray = Ray::towards(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0));
        let hit = bvh.nearest_hit(&objects, &ray, Method::Stable).unwrap();
        assert_eq!(hit.object, 0);
        assert!((hit.t - 1.6).abs() < 1e-12);
        assert!(bvh.blocked(&objects, &ray, 1.7, Method::Stable));
        assert!(!bvh.blocked(&objects, &ray, 1.5, Method::Stable));
    }

    #[test]
    fn the_objects_outside_the_tree_are_tested_too() {
        // Thirty balls off to the side, in the tree, and the floor (outside it,
        // the only loose object): a ray straight down from (0, 1, 0) meets only
        // the floor's top, 1.7 below.
        let mut objects: Vec<Object> = (0..30)
            .map(|i| ball(5.0 + f64::from(i % 6), 0.0, -f64::from(i / 6), 0.3))
            .collect();
        objects.push(Object {
            role: Role::Floor,
            ..ball(0.0, -1000.0, 0.0, 999.3)
        });
        let bvh = Bvh::build(&objects);
        assert_eq!(bvh.loose, vec![30]);
        let ray = Ray::towards(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, -1.0, 0.0));
        let hit = bvh.nearest_hit(&objects, &ray, Method::Stable).unwrap();
        assert_eq!(hit.object, 30);
        assert!((hit.t - 1.7).abs() < 1e-9, "{}", hit.t);
        assert!(bvh.blocked(&objects, &ray, 1.8, Method::Stable));
        assert!(!bvh.blocked(&objects, &ray, 1.6, Method::Stable));
    }

    #[test]
    fn a_row_of_64_spheres_along_any_axis_gives_the_balanced_tree_of_full_leaves() {
        // 64 spheres one apart on a line, listed in a shuffled order (37 is prime
        // to 64, so sphere i sits at 37·i mod 64). Sixteen bins of 64 centres
        // hold four each, and the surface area heuristic's cheapest boundary
        // halves the row at every level: the tree is the perfect one, 16 leaves of
        // four neighbours (LEAF) and 31 nodes. A split along the wrong axis, by
        // the list's order, would put strangers in a leaf; leaves of fewer than
        // LEAF spheres would need more nodes.
        assert_eq!(LEAF, 4);
        for axis in 0..3 {
            let objects: Vec<Object> = (0..64)
                .map(|i| {
                    let mut c = [0.0; 3];
                    c[axis] = f64::from((37 * i) % 64);
                    ball(c[0], c[1], c[2], 0.3)
                })
                .collect();
            let bvh = Bvh::build(&objects);
            assert_eq!(bvh.node_count(), 31, "along axis {axis}");
            assert_eq!(depth(&bvh, 0), 5);
            reaches_each_node_and_sphere_once(&bvh, 64);
            for n in bvh.nodes.iter().filter(|n| n.count > 0) {
                assert_eq!(n.count as usize, LEAF);
                let mut places: Vec<f64> = bvh.balls
                    [n.first as usize..(n.first + n.count) as usize]
                    .iter()
                    .map(|b| b[axis])
                    .collect();
                places.sort_by(f64::total_cmp);
                assert_eq!(places[0] % 4.0, 0.0, "leaf {places:?} along axis {axis}");
                assert_eq!(
                    places[3] - places[0],
                    3.0,
                    "leaf {places:?} along axis {axis}"
                );
            }
        }
    }

    #[test]
    fn of_two_equally_cheap_splits_the_lower_boundary_is_taken() {
        // Three columns of four spheres at x = −10, 0 and 10, mirror images of
        // each other: "left the first column" and "left the first two" cost
        // exactly the same (the boxes' areas mirror, bit for bit). `divide` takes
        // the lowest such boundary, so the root's first child is the first
        // column alone, a leaf.
        let objects: Vec<Object> = [-10.0, 0.0, 10.0]
            .into_iter()
            .flat_map(|x| (0..4).map(move |y| ball(x, f64::from(y), 0.0, 0.3)))
            .collect();
        let bvh = Bvh::build(&objects);
        let first = bvh.nodes[1];
        assert_eq!(first.count, 4, "the root's first child");
        let column: Vec<f64> = bvh.balls[first.first as usize..][..4]
            .iter()
            .map(|b| b[0])
            .collect();
        assert_eq!(column, [-10.0; 4]);
    }

    #[test]
    fn the_margin_is_the_rays_own_and_a_far_floor_does_not_widen_it() {
        let spheres: Vec<Object> = (0..100)
            .map(|i| ball(f64::from(i % 10), 0.0, -f64::from(i / 10) - 2.0, 0.01))
            .collect();
        let mut with_floor = spheres.clone();
        with_floor.push(Object {
            role: Role::Floor,
            ..ball(0.0, -9000.0, 0.0, 8999.3)
        });
        let (bare, floored) = (Bvh::build(&spheres), Bvh::build(&with_floor));
        assert_eq!(bare.size, floored.size);
        assert_eq!(floored.loose, vec![100]);
        // In float32, from the camera: a small fraction of a sphere's radius.
        let u = f64::from(f32::EPSILON) / 2.0;
        let near = floored.margin(u, Vec3::new(0.0, 0.0, 1.0));
        assert!(near < 0.01 / 10.0, "{near}");
        // From a point far out on the floor, larger in proportion.
        let far = floored.margin(u, Vec3::new(0.0, 0.0, 1000.0));
        assert!(far > 50.0 * near, "{far} {near}");
    }

    /// `below` as it was written with branches: the masked one gives the same
    /// bits for every finite or infinite `x`, so the boxes (and the tree) are
    /// the same.
    fn below_by_branches(x: f64) -> f32 {
        let r = x as f32;
        if f64::from(r) <= x {
            r
        } else if r > 0.0 {
            f32::from_bits(r.to_bits() - 1)
        } else if r < 0.0 {
            f32::from_bits(r.to_bits() + 1)
        } else {
            -f32::from_bits(1)
        }
    }

    #[test]
    fn the_masked_step_down_is_the_branching_one() {
        let mut special = vec![
            0.0,
            -0.0,
            1e-50,
            -1e-50,
            1e-45,
            -1e-45,
            f64::from(f32::MAX),
            -f64::from(f32::MAX),
            1e39,
            -1e39,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
        ];
        // Many more, spread over every exponent: bit patterns from a fixed
        // sequence, and their neighbours among float32s.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = f64::from_bits(state);
            if x.is_finite() {
                special.push(x);
                special.push(f64::from(x as f32));
            }
        }
        for x in special {
            assert_eq!(below(x).to_bits(), below_by_branches(x).to_bits(), "{x:e}");
        }
    }

    #[test]
    fn outward_rounding_brackets_the_float64_value() {
        for x in [
            0.1,
            -0.1,
            1e-50,
            -1e-50,
            0.0,
            3.0,
            -3.0,
            1e39,
            16777217.0,
            -16777217.0,
        ] {
            let (lo, hi) = (below(x), above(x));
            assert!(f64::from(lo) <= x && x <= f64::from(hi), "{x}: {lo} {hi}");
            // Equal where x is a float32, else neighbours: no float32 between.
            let middle = ((f64::from(lo) + f64::from(hi)) / 2.0) as f32;
            assert!(middle == lo || middle == hi, "{x}: {lo} {hi}");
        }
    }
}
