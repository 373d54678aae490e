//! The bounding volume hierarchy: `f32` node records shared by both tracers, built on
//! the host by one of two builders.
//!
//! - [`BuildMethod::Sah`]: top-down binned SAH (Wald, "On fast Construction of
//!   SAH-based Bounding Volume Hierarchies", IEEE Symposium on Interactive Ray Tracing
//!   2007): each node bins its primitives' centroids into [`SAH_BINS`] bins along the
//!   longest axis of their bounds and splits where `A_left·N_left + A_right·N_right` is
//!   smallest; the two subtrees of the top levels are built on separate threads. Where
//!   the SAH finds no split (all centroids in one bin) or the tree reaches
//!   [`MEDIAN_SPLIT_DEPTH`], it splits at the median by count instead, so any input,
//!   a million identical triangles included, builds in `O(n log n)` with a bounded depth.
//! - [`BuildMethod::MedianSplit`]: the object-median split on the longest centroid axis
//!   at every node: the simple baseline the SAH is measured against.
//!
//! obvhs (PLOC) was measured first and not kept: on this project's 2-core machines it
//! built 1M spread boxes at 1.4–2.4 M/s, and 100k identical boxes took 40 s and gave a
//! chain of depth 99,997 (`BENCHMARKS.md`).
//!
//! The tree is stored depth-first: node 0 is the root; an inner node's children are
//! `first` and `first + 1`; a leaf's primitives are `prims[first .. first + count]`.

use std::time::{Duration, Instant};

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3A, Vec4};

use super::geometry::PrimRef;
use super::wide::{WideNode, collapse};

/// Deepest binary tree the builders make (see [`MEDIAN_SPLIT_DEPTH`]): its collapse
/// into wide nodes is half as deep, which sizes the tracers' traversal stacks
/// ([`super::wide::MAX_TRAVERSAL_STACK`]).
pub const MAX_BVH_DEPTH: u32 = 64;

/// Most primitives in one leaf. Two: on lavapipe a triangle test costs about as much
/// as a wide node's visit (each reads its records lane by lane), and the bunny's trace
/// was 11% shorter with leaves of two than of four, the million-triangle terrain's 9%
/// (BENCHMARKS.md, "The compressed 4-wide BVH").
pub const MAX_LEAF_PRIMITIVES: u32 = 2;

/// Nodes that a median split turns into two leaves are split at their median on the
/// longest axis instead of by binned SAH: for so few primitives the bins cost more
/// than the choice gains (the builder's speed with leaves of two, BENCHMARKS.md).
const SMALL_NODE: usize = 2 * MAX_LEAF_PRIMITIVES as usize;

/// One node of the tree as both tracers read it (`BvhNode` in `shaders/types.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    /// Lower corner of the node's box.
    pub min: [f32; 3],
    /// Inner node: index of the first child (the second is `first + 1`). Leaf: index of
    /// its first primitive in [`Bvh::prims`].
    pub first: u32,
    /// Upper corner of the node's box.
    pub max: [f32; 3],
    /// Number of primitives of a leaf; 0 for an inner node.
    pub count: u32,
}

impl BvhNode {
    /// Whether the node is a leaf.
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// An axis-aligned box with `f32` corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb32 {
    /// Lower corner.
    pub min: [f32; 3],
    /// Upper corner.
    pub max: [f32; 3],
}

/// The largest `f32` not above `x` (`x` finite).
fn f32_at_or_below(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x { f.next_down() } else { f }
}

/// The smallest `f32` not below `x`.
fn f32_at_or_above(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) < x { f.next_up() } else { f }
}

impl Aabb32 {
    /// The box that contains nothing.
    pub const EMPTY: Self = Self {
        min: [f32::INFINITY; 3],
        max: [f32::NEG_INFINITY; 3],
    };

    /// The `f32` box around the `f64` box `lo..hi`, rounded outwards and padded on each
    /// axis by 2^-20 of the axis's magnitude plus its extent, which covers the rounding
    /// of the primitive to `f32` and the few ulps by which an `f32` intersection test
    /// may report a hit just outside the exact primitive.
    pub fn around(lo: DVec3, hi: DVec3) -> Self {
        let pad = (lo.abs().max(hi.abs()) + (hi - lo)) * (1.0 / 1_048_576.0);
        let lo = lo - pad;
        let hi = hi + pad;
        Self {
            min: [
                f32_at_or_below(lo.x),
                f32_at_or_below(lo.y),
                f32_at_or_below(lo.z),
            ],
            max: [
                f32_at_or_above(hi.x),
                f32_at_or_above(hi.y),
                f32_at_or_above(hi.z),
            ],
        }
    }

    /// The box around `points` and their `f32` roundings.
    pub fn around_points(points: &[DVec3]) -> Self {
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for p in points {
            let rounded = p.as_vec3().as_dvec3();
            lo = lo.min(*p).min(rounded);
            hi = hi.max(*p).max(rounded);
        }
        Self::around(lo, hi)
    }
}

/// Which builder makes the tree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum BuildMethod {
    /// Binned SAH: the default.
    #[default]
    Sah,
    /// Object-median split on the longest centroid axis: the baseline.
    MedianSplit,
}

/// Figures of one build.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BvhStats {
    /// The builder that made the tree.
    pub method: BuildMethod,
    /// Wall time of the build, flattening and the collapse to wide nodes included.
    pub build_time: Duration,
    /// Depth of the binary tree (a lone leaf has depth 1; an empty tree 0).
    pub depth: u32,
    /// Number of binary nodes.
    pub nodes: usize,
    /// Number of leaves.
    pub leaves: usize,
    /// The tree's SAH cost relative to its root box: `Σ inner area / root area +
    /// Σ leaf area × primitives / root area` (traversal and intersection cost 1 each).
    pub sah_cost: f64,
}

/// The hierarchy: depth-first binary nodes, the wide nodes the tracers walk, and the
/// primitive references of the leaves (which both share).
#[derive(Debug, Clone, Default)]
pub struct Bvh {
    /// The binary tree as built; node 0 is the root. Empty when there is no bounded
    /// primitive.
    pub nodes: Vec<BvhNode>,
    /// The same tree collapsed into compressed 4-wide nodes ([`super::wide`]), which
    /// both tracers traverse; node 0 is the root.
    pub wide: Vec<WideNode>,
    /// Primitive references, leaf by leaf.
    pub prims: Vec<PrimRef>,
    /// How it was built.
    pub stats: BvhStats,
}

/// A node of the tree being built, before flattening.
enum BuildNode {
    Inner {
        aabb: Aabb32,
        children: [usize; 2],
    },
    /// Primitives `order[start .. start + count]` of the whole build order.
    Leaf {
        aabb: Aabb32,
        start: usize,
        count: usize,
    },
}

impl Bvh {
    /// Builds the tree over `primitives` (each with its conservative box) with
    /// `method`; a tree deeper than [`MAX_BVH_DEPTH`] is rebuilt by median split.
    pub fn build(primitives: &[(PrimRef, Aabb32)], method: BuildMethod) -> Self {
        let start = Instant::now();
        let mut bvh = build_tree(primitives, method);
        bvh.wide = collapse(&bvh.nodes);
        bvh.stats.build_time = start.elapsed();
        bvh
    }

    /// The root box, if the tree is not empty.
    pub fn root_bounds(&self) -> Option<Aabb32> {
        self.nodes.first().map(|n| Aabb32 {
            min: n.min,
            max: n.max,
        })
    }
}

/// Bins per axis of the SAH split search.
pub const SAH_BINS: usize = 16;

/// Depth from which [`BuildMethod::Sah`] splits at the median by count: below it every
/// subtree of `n` primitives has depth at most `log2(n / MAX_LEAF_PRIMITIVES) + 1`, so
/// the whole tree stays within [`MAX_BVH_DEPTH`] for up to 2^30 primitives.
pub const MEDIAN_SPLIT_DEPTH: u32 = 30;

/// Subtrees with fewer primitives than this are built on the current thread.
const PARALLEL_THRESHOLD: usize = 50_000;

/// One primitive as the builders move it around: its box, with its position in the
/// input in the lower corner's fourth lane. Kept contiguous and reordered in place, so
/// each pass over a node's primitives reads memory in order; 32 bytes (the index in a
/// field of its own made it 48), as the passes over the primitives are bound by
/// memory.
#[derive(Debug, Clone, Copy)]
struct BuildPrim {
    /// The lower corner in `x, y, z`; `w` holds [`BuildPrim::INDEX_TAG`]` | index` as
    /// `f32` bits: never a subnormal, so the lane's arithmetic in
    /// [`BuildPrim::centroid`] (whose result no one reads) is never slow.
    min_and_index: Vec4,
    /// The upper corner.
    max: Vec3A,
}

impl BuildPrim {
    /// Bit 30 set: whatever the index below it, the tagged bits have a nonzero
    /// exponent, so they are never a subnormal.
    const INDEX_TAG: u32 = 1 << 30;

    /// The index bits: builds are of at most 2^30 primitives (as
    /// [`MEDIAN_SPLIT_DEPTH`]'s depth bound assumes; 32 GiB of these records).
    const INDEX_MASK: u32 = Self::INDEX_TAG - 1;

    fn new(index: u32, aabb: &Aabb32) -> Self {
        let tagged = f32::from_bits(Self::INDEX_TAG | (index & Self::INDEX_MASK));
        Self {
            min_and_index: Vec4::new(aabb.min[0], aabb.min[1], aabb.min[2], tagged),
            max: Vec3A::from_array(aabb.max),
        }
    }

    /// The lower corner.
    fn min(&self) -> Vec3A {
        Vec3A::from_vec4(self.min_and_index)
    }

    /// The position in the input.
    fn index(&self) -> usize {
        (self.min_and_index.w.to_bits() & Self::INDEX_MASK) as usize
    }

    /// Twice the box's centre: the factor cancels in every comparison.
    fn centroid(&self) -> Vec3A {
        self.min() + self.max
    }
}

/// A box during the build, in SIMD lanes (no NaN reaches the builder: validated
/// geometry only).
#[derive(Debug, Clone, Copy)]
struct SimdBox {
    min: Vec3A,
    max: Vec3A,
}

impl SimdBox {
    const EMPTY: Self = Self {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };

    fn union(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    fn half_area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    fn to_aabb(self) -> Aabb32 {
        Aabb32 {
            min: self.min.to_array(),
            max: self.max.to_array(),
        }
    }
}

/// The bounds a node is built with: its primitives' box and their centroids' box.
#[derive(Debug, Clone, Copy)]
struct NodeBounds {
    boxes: SimdBox,
    centroids: SimdBox,
}

impl NodeBounds {
    const EMPTY: Self = Self {
        boxes: SimdBox::EMPTY,
        centroids: SimdBox::EMPTY,
    };

    fn add(&mut self, prim: &BuildPrim) {
        self.boxes.min = self.boxes.min.min(prim.min());
        self.boxes.max = self.boxes.max.max(prim.max);
        let centroid = prim.centroid();
        self.centroids.min = self.centroids.min.min(centroid);
        self.centroids.max = self.centroids.max.max(centroid);
    }

    fn union(&self, other: &Self) -> Self {
        Self {
            boxes: self.boxes.union(&other.boxes),
            centroids: self.centroids.union(&other.centroids),
        }
    }

    fn of(prims: &[BuildPrim]) -> Self {
        let mut bounds = Self::EMPTY;
        prims.iter().for_each(|p| bounds.add(p));
        bounds
    }
}

fn build_tree(primitives: &[(PrimRef, Aabb32)], method: BuildMethod) -> Bvh {
    if primitives.is_empty() {
        return Bvh::default();
    }
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    // The root's bounds are gathered in the same pass that makes the records.
    let mut bounds = NodeBounds::EMPTY;
    let mut prims: Vec<BuildPrim> = primitives
        .iter()
        .enumerate()
        .map(|(i, (_, b))| {
            let prim = BuildPrim::new(i as u32, b);
            bounds.add(&prim);
            prim
        })
        .collect();
    let mut arena = Vec::with_capacity(2 * primitives.len() / MAX_LEAF_PRIMITIVES as usize + 1);
    build_subtree(method, &mut prims, bounds, 0, 1, threads, &mut arena);
    let order = build_order(primitives, &prims, threads);
    drop(prims);
    let mut bvh = flatten(&arena, order, threads);
    bvh.stats.method = method;
    bvh
}

/// The primitive references in the order the build left `prims` in, `threads` runs
/// at once.
fn build_order(
    primitives: &[(PrimRef, Aabb32)],
    prims: &[BuildPrim],
    threads: usize,
) -> Vec<PrimRef> {
    let mut order = vec![PrimRef(0); prims.len()];
    let chunk = prims
        .len()
        .div_ceil(if prims.len() >= PARALLEL_THRESHOLD {
            threads.max(1)
        } else {
            1
        })
        .max(1);
    std::thread::scope(|scope| {
        let mut runs = order.chunks_mut(chunk).zip(prims.chunks(chunk));
        let first = runs.next();
        for (out, run) in runs {
            scope.spawn(move || fill_order(primitives, run, out));
        }
        if let Some((out, run)) = first {
            fill_order(primitives, run, out);
        }
    });
    order
}

/// `out[i]` = the reference of `prims[i]`.
fn fill_order(primitives: &[(PrimRef, Aabb32)], prims: &[BuildPrim], out: &mut [PrimRef]) {
    for (slot, prim) in out.iter_mut().zip(prims) {
        *slot = primitives[prim.index()].0;
    }
}

/// Reorders `prims` for a split and returns how many go left (between 1 and
/// `prims.len() - 1`) with both children's bounds.
fn split(
    method: BuildMethod,
    prims: &mut [BuildPrim],
    bounds: &NodeBounds,
    depth: u32,
) -> (usize, NodeBounds, NodeBounds) {
    let centroids = &bounds.centroids;
    let extent = (centroids.max - centroids.min).to_array();
    let axis = (0..3)
        .max_by(|&a, &b| extent[a].total_cmp(&extent[b]))
        .unwrap_or(0);
    let median = |prims: &mut [BuildPrim]| {
        let mid = prims.len() / 2;
        // Ties (identical centroids) are split by count all the same.
        prims.select_nth_unstable_by(mid, |x, y| {
            x.centroid()[axis].total_cmp(&y.centroid()[axis])
        });
        (
            mid,
            NodeBounds::of(&prims[..mid]),
            NodeBounds::of(&prims[mid..]),
        )
    };
    if method == BuildMethod::MedianSplit
        || prims.len() <= SMALL_NODE
        || depth >= MEDIAN_SPLIT_DEPTH
        || extent[axis].is_nan()
        || extent[axis] <= 0.0
    {
        return median(prims);
    }
    // Bin the centroids along the axis (Wald 2007, §3).
    let scale = SAH_BINS as f32 / extent[axis];
    let origin = centroids.min[axis];
    let bin_of =
        |p: &BuildPrim| (((p.centroid()[axis] - origin) * scale) as usize).min(SAH_BINS - 1);
    let mut bins = [(NodeBounds::EMPTY, 0usize); SAH_BINS];
    for p in prims.iter() {
        let bin = &mut bins[bin_of(p)];
        bin.0.add(p);
        bin.1 += 1;
    }
    // The cost of every plane between bins: sweep from the right, then from the left.
    let mut right = [(NodeBounds::EMPTY, 0usize); SAH_BINS];
    let mut acc = (NodeBounds::EMPTY, 0usize);
    for b in (1..SAH_BINS).rev() {
        acc = (acc.0.union(&bins[b].0), acc.1 + bins[b].1);
        right[b] = acc;
    }
    let mut best: Option<(f32, usize, NodeBounds)> = None;
    let mut acc = (NodeBounds::EMPTY, 0usize);
    for b in 0..SAH_BINS - 1 {
        acc = (acc.0.union(&bins[b].0), acc.1 + bins[b].1);
        if acc.1 == 0 || acc.1 == prims.len() {
            continue;
        }
        let cost = acc.0.boxes.half_area() * acc.1 as f32
            + right[b + 1].0.boxes.half_area() * right[b + 1].1 as f32;
        if best.is_none_or(|(c, _, _)| cost < c) {
            best = Some((cost, b, acc.0));
        }
    }
    let Some((_, plane, left_bounds)) = best.filter(|(c, _, _)| c.is_finite()) else {
        return median(prims);
    };
    // Partition in place: bins 0..=plane go left.
    let mut left = 0;
    for k in 0..prims.len() {
        if bin_of(&prims[k]) <= plane {
            prims.swap(left, k);
            left += 1;
        }
    }
    (left, left_bounds, right[plane + 1].0)
}

/// Builds the subtree over `prims` (whose first entry is entry `offset` of the whole
/// build order, and whose bounds are `bounds`) into `arena` and returns its index
/// there. With `threads > 1` and enough primitives, the right child is built on a
/// second thread.
fn build_subtree(
    method: BuildMethod,
    prims: &mut [BuildPrim],
    bounds: NodeBounds,
    offset: usize,
    depth: u32,
    threads: usize,
    arena: &mut Vec<BuildNode>,
) -> usize {
    let index = arena.len();
    if prims.len() <= MAX_LEAF_PRIMITIVES as usize {
        arena.push(BuildNode::Leaf {
            aabb: bounds.boxes.to_aabb(),
            start: offset,
            count: prims.len(),
        });
        return index;
    }
    let parallel = threads > 1 && prims.len() >= PARALLEL_THRESHOLD;
    let (mid, left_bounds, right_bounds) = split(method, prims, &bounds, depth);
    arena.push(BuildNode::Inner {
        aabb: bounds.boxes.to_aabb(),
        children: [usize::MAX; 2],
    });
    let (left, right) = prims.split_at_mut(mid);
    let children = if parallel {
        let mut right_arena = Vec::new();
        let left_root = std::thread::scope(|scope| {
            let worker = scope.spawn(|| {
                let half = threads / 2;
                let at = offset + mid;
                build_subtree(
                    method,
                    right,
                    right_bounds,
                    at,
                    depth + 1,
                    half,
                    &mut right_arena,
                )
            });
            let rest = threads - threads / 2;
            let left_root =
                build_subtree(method, left, left_bounds, offset, depth + 1, rest, arena);
            // A panic in the worker is a bug in this builder: raise it here.
            if let Err(panic) = worker.join() {
                std::panic::resume_unwind(panic);
            }
            left_root
        });
        [left_root, append_arena(arena, right_arena)]
    } else {
        let left_root = build_subtree(method, left, left_bounds, offset, depth + 1, 1, arena);
        let right_root = build_subtree(
            method,
            right,
            right_bounds,
            offset + mid,
            depth + 1,
            1,
            arena,
        );
        [left_root, right_root]
    };
    if let BuildNode::Inner { children: c, .. } = &mut arena[index] {
        *c = children;
    }
    index
}

/// Appends a subtree built into its own arena (root at 0), shifting its child
/// indices, and returns where its root landed.
fn append_arena(arena: &mut Vec<BuildNode>, subtree: Vec<BuildNode>) -> usize {
    let shift = arena.len();
    arena.extend(subtree.into_iter().map(|node| match node {
        BuildNode::Inner { aabb, children } => BuildNode::Inner {
            aabb,
            children: children.map(|c| c + shift),
        },
        leaf => leaf,
    }));
    shift
}

/// Lays a built tree out depth-first with sibling pairs adjacent (a node's children
/// come before its left child's descendants, which come before its right child's),
/// the leaves' primitives (`order`, the build order) in the same order, and measures
/// it.
///
/// The builder numbers the primitives left to right, as this layout visits the
/// leaves, so `order` is already the leaves' primitives in layout order and a leaf's
/// first primitive is its start in the build order. The arena is in preorder (a
/// node, its left subtree, its right subtree), so a subtree's size is the distance
/// between its children: every subtree's slots are known before it is laid out, and
/// the two halves of the top levels are laid out on separate threads.
fn flatten(tree: &[BuildNode], order: Vec<PrimRef>, threads: usize) -> Bvh {
    let mut nodes = vec![BvhNode::zeroed(); tree.len()];
    nodes[0] = record(tree, 0, 1);
    let (depth, leaves) = match tree[0] {
        BuildNode::Leaf { .. } => (1, 1),
        BuildNode::Inner { .. } => {
            let layout = Layout { tree, threads };
            layout.place_children(0, tree.len(), 1, 1, &mut nodes[1..])
        }
    };
    let area = |n: &BvhNode| {
        let e = [0, 1, 2].map(|a| f64::from(n.max[a]) - f64::from(n.min[a]));
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    };
    let root_area = area(&nodes[0]).max(f64::MIN_POSITIVE);
    // Summed in layout order, one node after the other, as it always was.
    let sah_cost = nodes
        .iter()
        .map(|n| area(n) / root_area * if n.is_leaf() { f64::from(n.count) } else { 1.0 })
        .sum();
    Bvh {
        stats: BvhStats {
            depth,
            nodes: nodes.len(),
            leaves,
            sah_cost,
            ..BvhStats::default()
        },
        nodes,
        wide: Vec::new(),
        prims: order,
    }
}

/// The record of arena node `source`, whose children (if it has any) go to slot
/// `first_child` of the layout.
fn record(tree: &[BuildNode], source: usize, first_child: usize) -> BvhNode {
    match &tree[source] {
        BuildNode::Inner { aabb, .. } => BvhNode {
            min: aabb.min,
            first: u32::try_from(first_child).unwrap_or(u32::MAX),
            max: aabb.max,
            count: 0,
        },
        BuildNode::Leaf { aabb, start, count } => BvhNode {
            min: aabb.min,
            first: u32::try_from(*start).unwrap_or(u32::MAX),
            max: aabb.max,
            count: *count as u32,
        },
    }
}

/// Subtrees of fewer nodes than this are laid out on the current thread.
const PARALLEL_LAYOUT_THRESHOLD: usize = 20_000;

/// What [`flatten`]'s layout reads: the built tree and how many threads it may use.
struct Layout<'a> {
    tree: &'a [BuildNode],
    threads: usize,
}

impl Layout<'_> {
    /// Lays out the descendants of the inner arena node `source` (whose subtree has
    /// `size` nodes, at binary depth `depth`) into `out`, which is slots `base ..
    /// base + size - 1` of the layout, its two children first. Returns the deepest
    /// depth below it and its number of leaves.
    fn place_children(
        &self,
        source: usize,
        size: usize,
        depth: u32,
        base: usize,
        out: &mut [BvhNode],
    ) -> (u32, usize) {
        let BuildNode::Inner { children, .. } = self.tree[source] else {
            return (depth, 1);
        };
        let [left, right] = children;
        // Preorder: the left subtree fills the arena up to the right child.
        let left_size = right - left;
        let right_size = size - 1 - left_size;
        let left_base = base + 2;
        let right_base = left_base + left_size - 1;
        out[0] = record(self.tree, left, left_base);
        out[1] = record(self.tree, right, right_base);
        let (left_out, right_out) = out[2..].split_at_mut(left_size - 1);
        let place = |source, size, base, out: &mut [BvhNode], threads| {
            let layout = Layout {
                tree: self.tree,
                threads,
            };
            layout.place_children(source, size, depth + 1, base, out)
        };
        let ((left_depth, left_leaves), (right_depth, right_leaves)) = if self.threads > 1
            && size >= PARALLEL_LAYOUT_THRESHOLD
        {
            let half = self.threads / 2;
            let rest = self.threads - half;
            std::thread::scope(|scope| {
                let worker = scope.spawn(|| place(right, right_size, right_base, right_out, half));
                let left = place(left, left_size, left_base, left_out, rest);
                // A panic in the worker is a bug in this layout: raise it here.
                match worker.join() {
                    Ok(right) => (left, right),
                    Err(panic) => std::panic::resume_unwind(panic),
                }
            })
        } else {
            (
                place(left, left_size, left_base, left_out, 1),
                place(right, right_size, right_base, right_out, 1),
            )
        };
        (left_depth.max(right_depth), left_leaves + right_leaves)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::geometry::PrimKind;

    fn boxes(n: usize, spread: f64) -> Vec<(PrimRef, Aabb32)> {
        (0..n)
            .map(|i| {
                let x = ((i * 7919) % 1000) as f64 * spread;
                let y = ((i * 104_729) % 997) as f64 * spread;
                let c = DVec3::new(x, y, (i % 13) as f64);
                (
                    PrimRef::new(PrimKind::Triangle, i as u32),
                    Aabb32::around(c - 0.5, c + 0.5),
                )
            })
            .collect()
    }

    /// Every primitive is in exactly one leaf, every node contains its children and
    /// its primitives, and the depth bound holds.
    fn check_tree(bvh: &Bvh, primitives: &[(PrimRef, Aabb32)]) {
        let mut seen = vec![0u32; primitives.len()];
        let contains = |outer: &BvhNode, inner_min: [f32; 3], inner_max: [f32; 3]| {
            (0..3).all(|a| outer.min[a] <= inner_min[a] && outer.max[a] >= inner_max[a])
        };
        for node in &bvh.nodes {
            if node.is_leaf() {
                assert!(node.count <= MAX_LEAF_PRIMITIVES);
                for p in &bvh.prims[node.first as usize..(node.first + node.count) as usize] {
                    seen[p.index()] += 1;
                    let b = primitives[p.index()].1;
                    assert!(contains(node, b.min, b.max));
                }
            } else {
                for child in [node.first, node.first + 1] {
                    let c = bvh.nodes[child as usize];
                    assert!(contains(node, c.min, c.max));
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
        assert!(bvh.stats.depth <= MAX_BVH_DEPTH);
    }

    /// The layout as it was first written (a stack of pending nodes, each leaf's
    /// primitives copied in visiting order), the reference [`flatten`] must match.
    fn reference_flatten(
        tree: &[BuildNode],
        order: &[PrimRef],
    ) -> (Vec<BvhNode>, Vec<PrimRef>, u32) {
        let aabb_of = |node: &BuildNode| match node {
            BuildNode::Inner { aabb, .. } | BuildNode::Leaf { aabb, .. } => *aabb,
        };
        let record = |aabb: Aabb32| BvhNode {
            min: aabb.min,
            first: 0,
            max: aabb.max,
            count: 0,
        };
        let mut nodes = vec![record(aabb_of(&tree[0]))];
        let mut prims = Vec::new();
        let mut deepest = 0;
        let mut pending = vec![(0usize, 0usize, 1u32)];
        while let Some((source, slot, depth)) = pending.pop() {
            deepest = deepest.max(depth);
            match &tree[source] {
                BuildNode::Leaf { start, count, .. } => {
                    nodes[slot].first = prims.len() as u32;
                    nodes[slot].count = *count as u32;
                    prims.extend_from_slice(&order[*start..*start + *count]);
                }
                BuildNode::Inner { children, .. } => {
                    let first = nodes.len();
                    nodes[slot].first = first as u32;
                    for &child in children {
                        nodes.push(record(aabb_of(&tree[child])));
                    }
                    pending.push((children[1], first + 1, depth + 1));
                    pending.push((children[0], first, depth + 1));
                }
            }
        }
        (nodes, prims, deepest)
    }

    #[test]
    fn the_parallel_layout_matches_the_stack_layout() {
        // Enough primitives for the build and the layout to use two threads.
        let prims = boxes(120_000, 0.37);
        let mut records: Vec<BuildPrim> = prims
            .iter()
            .enumerate()
            .map(|(i, (_, b))| BuildPrim::new(i as u32, b))
            .collect();
        assert!(records.iter().enumerate().all(|(i, r)| r.index() == i));
        let bounds = NodeBounds::of(&records);
        let mut arena = Vec::new();
        build_subtree(BuildMethod::Sah, &mut records, bounds, 0, 1, 2, &mut arena);
        let order: Vec<PrimRef> = records.iter().map(|r| prims[r.index()].0).collect();
        let (nodes, leaf_prims, depth) = reference_flatten(&arena, &order);
        for threads in [1, 2, 3] {
            let bvh = flatten(&arena, order.clone(), threads);
            assert_eq!(bvh.nodes, nodes);
            assert_eq!(bvh.prims, leaf_prims);
            assert_eq!(bvh.stats.depth, depth);
            assert_eq!(
                bvh.stats.leaves,
                nodes.iter().filter(|n| n.is_leaf()).count()
            );
        }
    }

    #[test]
    fn both_builders_make_valid_trees() {
        for n in [1, 2, 5, 100, 3000] {
            let prims = boxes(n, 0.1);
            for method in [BuildMethod::Sah, BuildMethod::MedianSplit] {
                let bvh = Bvh::build(&prims, method);
                check_tree(&bvh, &prims);
                assert_eq!(bvh.stats.nodes, bvh.nodes.len());
            }
        }
        assert!(Bvh::build(&[], BuildMethod::Sah).nodes.is_empty());
    }

    #[test]
    fn identical_primitives_build_a_shallow_tree() {
        let one = Aabb32::around(DVec3::ZERO, DVec3::ONE);
        let prims: Vec<_> = (0..100_000)
            .map(|i| (PrimRef::new(PrimKind::Triangle, i), one))
            .collect();
        let bvh = Bvh::build(&prims, BuildMethod::Sah);
        check_tree(&bvh, &prims);
        assert!(bvh.stats.depth <= 20, "depth {}", bvh.stats.depth);
    }

    #[test]
    fn sah_beats_the_median_split_on_clustered_input() {
        // Two dense clusters far apart plus a sparse line: the SAH tree's cost is lower.
        let mut prims = boxes(2000, 0.001);
        prims.extend(boxes(2000, 0.001).into_iter().map(|(p, b)| {
            let shift = |v: [f32; 3]| [v[0] + 1000.0, v[1], v[2]];
            (
                PrimRef::new(PrimKind::Triangle, p.index() as u32 + 2000),
                Aabb32 {
                    min: shift(b.min),
                    max: shift(b.max),
                },
            )
        }));
        let sah = Bvh::build(&prims, BuildMethod::Sah);
        let median = Bvh::build(&prims, BuildMethod::MedianSplit);
        assert!(
            sah.stats.sah_cost < median.stats.sah_cost,
            "{} vs {}",
            sah.stats.sah_cost,
            median.stats.sah_cost
        );
    }

    #[test]
    fn boxes_round_outwards() {
        let b = Aabb32::around(DVec3::splat(0.1), DVec3::splat(0.3));
        assert!(f64::from(b.min[0]) < 0.1 && f64::from(b.max[0]) > 0.3);
        let flat = Aabb32::around(DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 0.0));
        assert!(flat.min[2] <= 0.0 && flat.max[2] >= 0.0);
    }
}
