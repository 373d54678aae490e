//! The compressed 4-wide BVH both tracers walk: the binary SAH tree ([`super::bvh`])
//! collapsed so that each node holds up to [`WIDTH`] children, their boxes quantized
//! to 8 bits per coordinate relative to the node's own box.
//!
//! The layout follows Ylitie, Karras and Laine, "Efficient Incoherent Ray Traversal
//! on GPUs Through Compressed Wide BVHs" (HPG 2017, §3.1), at width 4 instead of 8: a
//! node stores an `f32` origin (its box's lower corner) and per axis a power-of-two
//! step `2^e`; child `i`'s box on that axis is `origin + q · 2^e` for its two 8-bit
//! numbers `q`, rounded outwards by the builder so that the decoded box contains the
//! child. A node is 64 bytes where four binary nodes' boxes took 128, and a traversal
//! step tests four boxes loaded together instead of two.
//!
//! Decoding is exact on both tracers and on any GPU: `q · 2^e` is exact in `f32` (an
//! 8-bit integer times a power of two), so `origin + q · 2^e` rounds once whether or
//! not a compiler fuses it into a multiply-add, and the CPU computes the same `f32`
//! sum ([`WideNode::child_box`], twin of `child_entries` in `shaders/traverse.wgsl`).
//!
//! The binary tree is collapsed top-down (Ylitie et al. §3.2 choose the children by
//! dynamic programming over the SAH; this takes the simpler greedy rule): a node starts
//! with its two binary children and repeatedly opens the inner child of smallest depth
//! (the largest box among those) until it has four or only leaves. Opening the
//! shallowest first consumes at least two binary levels per wide level on every path,
//! so a binary tree within [`MAX_BVH_DEPTH`] gives a wide one within
//! [`MAX_WIDE_DEPTH`], and a traversal stack of [`MAX_TRAVERSAL_STACK`] entries (three
//! waiting siblings per level) never overflows.

use bytemuck::{Pod, Zeroable};
use glam::Vec4;

use super::bvh::{Aabb32, BvhNode, MAX_BVH_DEPTH};

/// Children per node.
pub const WIDTH: usize = 4;

/// Deepest wide tree: half the binary bound ([`MAX_BVH_DEPTH`]), as the collapse opens
/// at least two binary levels per wide level.
pub const MAX_WIDE_DEPTH: u32 = MAX_BVH_DEPTH / 2;

/// Entries of a traversal stack: at most `WIDTH - 1` waiting siblings per level of a
/// tree of [`MAX_WIDE_DEPTH`] levels.
pub const MAX_TRAVERSAL_STACK: u32 = (WIDTH as u32 - 1) * MAX_WIDE_DEPTH;

/// The child word of an unused slot.
pub const EMPTY_CHILD: u32 = u32::MAX;

/// A child word's primitive count (0 for an inner node) sits above this bit.
pub const CHILD_COUNT_SHIFT: u32 = 29;

/// A child word's index bits: a node index, or a leaf's first primitive.
pub const CHILD_INDEX_MASK: u32 = (1 << CHILD_COUNT_SHIFT) - 1;

/// One node of the wide tree as both tracers read it (`WideNode` in
/// `shaders/types.wgsl`). The byte `i` of `low[a]` and `high[a]` holds child `i`'s
/// quantized lower and upper bound on axis `a`; byte `a` of `exponents` the biased
/// `f32` exponent of that axis's step.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct WideNode {
    /// The node box's lower corner: where every child's quantized bound counts from.
    pub origin: [f32; 3],
    /// Per axis (bytes 0, 1, 2) the biased exponent `e + 127` of the step `2^e`.
    pub exponents: u32,
    /// Per axis the four children's quantized lower bounds, child `i` in byte `i`.
    pub low: [u32; 3],
    /// Unused (keeps `high` 16-byte aligned, as WGSL lays out `vec3`).
    pub spare_low: u32,
    /// Per axis the four children's quantized upper bounds, child `i` in byte `i`.
    pub high: [u32; 3],
    /// Unused.
    pub spare_high: u32,
    /// The children's words ([`WideChild::word`]), [`EMPTY_CHILD`] for unused slots.
    pub children: [u32; WIDTH],
}

/// What a child slot of a [`WideNode`] holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WideChild {
    /// Nothing.
    Empty,
    /// The wide node of this index.
    Node(u32),
    /// The primitives `prims[first .. first + count]` of the tree.
    Leaf {
        /// Index of the leaf's first primitive reference.
        first: u32,
        /// Its number of primitives, 1 to [`super::MAX_LEAF_PRIMITIVES`].
        count: u32,
    },
}

impl WideChild {
    /// The child a word names (twin of `enter_child` in `shaders/traverse.wgsl`).
    pub fn from_word(word: u32) -> Self {
        if word == EMPTY_CHILD {
            return Self::Empty;
        }
        let index = word & CHILD_INDEX_MASK;
        match word >> CHILD_COUNT_SHIFT {
            0 => Self::Node(index),
            count => Self::Leaf {
                first: index,
                count,
            },
        }
    }

    /// The word that names the child: its count above [`CHILD_COUNT_SHIFT`] (0 for a
    /// node), its index below.
    pub fn word(self) -> u32 {
        match self {
            Self::Empty => EMPTY_CHILD,
            Self::Node(index) => index & CHILD_INDEX_MASK,
            Self::Leaf { first, count } => {
                (count << CHILD_COUNT_SHIFT) | (first & CHILD_INDEX_MASK)
            }
        }
    }
}

/// `origin + q · step` in `f32`: exact product, one rounding (twin of `dequantize` in
/// `shaders/traverse.wgsl`).
fn dequantize(origin: f32, step: f32, q: u32) -> f32 {
    origin + q as f32 * step
}

/// The step `2^(biased - 127)` of a biased exponent.
fn step_of(biased: u32) -> f32 {
    f32::from_bits(biased << 23)
}

/// The quantization of one axis of a node whose box spans `[lo, hi]`: the smallest
/// biased exponent whose 255 steps from `lo` reach `hi` (in the decoder's arithmetic).
fn axis_exponent(lo: f32, hi: f32) -> u32 {
    let extent = f64::from(hi) - f64::from(lo);
    let mut biased = if extent > 0.0 {
        (ceil_log2(extent / 255.0) + 127).clamp(1, 254) as u32
    } else {
        1
    };
    // The estimate may be one too large or, where the decoder's sum rounds down, one
    // too small. The decoded reach grows with the exponent, so these steps end on the
    // smallest exponent that reaches `hi` whatever the estimate.
    while biased > 1 && dequantize(lo, step_of(biased - 1), 255) >= hi {
        biased -= 1;
    }
    while biased < 254 && dequantize(lo, step_of(biased), 255) < hi {
        biased += 1;
    }
    biased
}

/// `ceil(log2(x))` for a positive normal `x`, read from its bits: the exponent, plus
/// one unless `x` is a power of two. Exact, and far cheaper than `log2` (three calls
/// per wide node); [`axis_exponent`] corrects its result in any case.
fn ceil_log2(x: f64) -> i64 {
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let fraction = bits & ((1 << 52) - 1);
    if fraction == 0 {
        exponent
    } else {
        exponent + 1
    }
}

/// `(x - origin) / step` truncated into `0..=255`: the first guess at `x`'s quantized
/// value, which [`quantize_down`] and [`quantize_up`] correct. `1 / step` is a power
/// of two, so a product replaces the division; the saturating cast replaces `floor`
/// and `ceil` (library calls on the baseline x86-64 target) at the cost of at most
/// one more correction step.
fn quantize_estimate(origin: f32, inverse_step: f64, x: f32) -> u32 {
    (((f64::from(x) - f64::from(origin)) * inverse_step) as u32).min(255)
}

/// The largest `q` whose decoded value is at or below `x` (0 if none is: the origin
/// lies at or below every child's bound). The decoded value grows with `q`, so the
/// corrections end on that `q` whatever the estimate.
fn quantize_down(origin: f32, step: f32, inverse_step: f64, x: f32) -> u32 {
    let mut q = quantize_estimate(origin, inverse_step, x);
    while q > 0 && dequantize(origin, step, q) > x {
        q -= 1;
    }
    while q < 255 && dequantize(origin, step, q + 1) <= x {
        q += 1;
    }
    q
}

/// The smallest `q` whose decoded value is at or above `x` (255 if none is: the
/// exponent was chosen so that 255 reaches the node's upper bound).
fn quantize_up(origin: f32, step: f32, inverse_step: f64, x: f32) -> u32 {
    let mut q = quantize_estimate(origin, inverse_step, x);
    while q < 255 && dequantize(origin, step, q) < x {
        q += 1;
    }
    while q > 0 && dequantize(origin, step, q - 1) >= x {
        q -= 1;
    }
    q
}

/// The quantized bounds on `axis` of up to [`WIDTH`] `children` of a node whose axis
/// starts at `origin` with steps `step`: [`quantize_down`] of each lower bound and
/// [`quantize_up`] of each upper bound (slots past the children hold nothing useful).
///
/// The four children are estimated and checked together in SIMD lanes: an estimate
/// is kept where the decoder's own arithmetic confirms it is the value the scalar
/// search defines (its decoded bound on the right side of the child's, the next
/// value's on the wrong side), which is almost always; any other slot takes the
/// scalar search. So the result is the scalar one, at a fraction of its cost.
fn quantize_children(
    origin: f32,
    step: f32,
    children: &[(WideChild, Aabb32)],
    axis: usize,
) -> ([u32; WIDTH], [u32; WIDTH]) {
    let mut lows = [origin; WIDTH];
    let mut highs = [origin; WIDTH];
    for (slot, (_, aabb)) in children.iter().enumerate().take(WIDTH) {
        lows[slot] = aabb.min[axis];
        highs[slot] = aabb.max[axis];
    }
    let (x_low, x_high) = (Vec4::from_array(lows), Vec4::from_array(highs));
    let (origin4, step4) = (Vec4::splat(origin), Vec4::splat(step));
    // `step` is a power of two: its inverse is exact (subnormal at worst).
    let inverse4 = Vec4::splat(1.0 / step);
    // Twin of `dequantize`: an exact product, then one rounding.
    let decode = |q: Vec4| origin4 + q * step4;
    let (zero, top) = (Vec4::ZERO, Vec4::splat(255.0));
    let q_low = ((x_low - origin4) * inverse4).floor().clamp(zero, top);
    let q_high = ((x_high - origin4) * inverse4).ceil().clamp(zero, top);
    // quantize_down's answer: the largest q decoding at or below x (0 if none).
    let low_ok = (q_low.cmpeq(zero) | decode(q_low).cmple(x_low))
        & (q_low.cmpeq(top) | decode(q_low + Vec4::ONE).cmpgt(x_low));
    // quantize_up's answer: the smallest q decoding at or above x (255 if none).
    let high_ok = (q_high.cmpeq(top) | decode(q_high).cmpge(x_high))
        & (q_high.cmpeq(zero) | decode(q_high - Vec4::ONE).cmplt(x_high));
    let mut low = q_low.as_uvec4().to_array();
    let mut high = q_high.as_uvec4().to_array();
    let used = children.len().min(WIDTH);
    let all = (1 << used) - 1;
    let inverse_step = 1.0 / f64::from(step);
    if (low_ok & high_ok).bitmask() & all != all {
        for slot in 0..used {
            low[slot] = quantize_down(origin, step, inverse_step, lows[slot]);
            high[slot] = quantize_up(origin, step, inverse_step, highs[slot]);
        }
    }
    for slot in 0..used {
        debug_assert_eq!(
            (low[slot], high[slot]),
            (
                quantize_down(origin, step, inverse_step, lows[slot]),
                quantize_up(origin, step, inverse_step, highs[slot])
            ),
            "the lanes' estimate is the scalar search's answer"
        );
    }
    (low, high)
}

/// A lower box bound the decoder reads the same way with or without flushing
/// subnormals: a subnormal is replaced by the nearest normal or zero below it.
fn normal_or_zero_below(x: f32) -> f32 {
    if x.is_subnormal() {
        if x > 0.0 { 0.0 } else { -f32::MIN_POSITIVE }
    } else {
        x
    }
}

impl WideNode {
    /// The node with box `bounds` and `children` (each with its box), at most
    /// [`WIDTH`]; the other slots are empty.
    pub fn new(bounds: Aabb32, children: &[(WideChild, Aabb32)]) -> Self {
        assert!(
            children.len() <= WIDTH,
            "a wide node has at most {WIDTH} children"
        );
        let origin = bounds.min.map(normal_or_zero_below);
        let mut node = Self {
            origin,
            exponents: 0,
            low: [0; 3],
            spare_low: 0,
            high: [0; 3],
            spare_high: 0,
            children: [EMPTY_CHILD; WIDTH],
        };
        for (axis, &start) in origin.iter().enumerate() {
            let biased = axis_exponent(start, bounds.max[axis]);
            node.exponents |= biased << (8 * axis);
            let step = step_of(biased);
            let (lows, highs) = quantize_children(start, step, children, axis);
            for slot in 0..children.len() {
                node.low[axis] |= lows[slot] << (8 * slot);
                node.high[axis] |= highs[slot] << (8 * slot);
            }
            // Empty slots: an inverted box, never read (the child word says empty).
            for slot in children.len()..WIDTH {
                node.low[axis] |= 0xff << (8 * slot);
            }
        }
        for (slot, (child, _)) in children.iter().enumerate() {
            node.children[slot] = child.word();
        }
        node
    }

    /// What slot `slot` holds.
    pub fn child(&self, slot: usize) -> WideChild {
        WideChild::from_word(self.children[slot])
    }

    /// Slot `slot`'s box as both tracers decode it (it contains the child's own box).
    pub fn child_box(&self, slot: usize) -> Aabb32 {
        let mut aabb = Aabb32 {
            min: [0.0; 3],
            max: [0.0; 3],
        };
        for axis in 0..3 {
            let step = step_of((self.exponents >> (8 * axis)) & 0xff);
            let byte = |word: u32| (word >> (8 * slot)) & 0xff;
            aabb.min[axis] = dequantize(self.origin[axis], step, byte(self.low[axis]));
            aabb.max[axis] = dequantize(self.origin[axis], step, byte(self.high[axis]));
        }
        aabb
    }

    /// The node with its inner children's indices shifted by `first_node` and its
    /// leaves' by `first_prim`: where a mesh's tree lands in the GPU's buffers.
    pub fn shifted(&self, first_node: u32, first_prim: u32) -> Self {
        let mut node = *self;
        for word in &mut node.children {
            *word = match WideChild::from_word(*word) {
                WideChild::Empty => EMPTY_CHILD,
                WideChild::Node(index) => WideChild::Node(index + first_node).word(),
                WideChild::Leaf { first, count } => WideChild::Leaf {
                    first: first + first_prim,
                    count,
                }
                .word(),
            };
        }
        node
    }
}

/// The binary tree `nodes` (depth-first, an inner node's children at `first` and
/// `first + 1`) collapsed into wide nodes, node 0 the root. A binary leaf keeps its
/// primitive range, so the wide tree shares the binary tree's primitive order.
///
/// Two passes: `plan` walks the tree once, choosing each wide node's children and
/// numbering the wide nodes; `encode` then quantizes every node on its own, which
/// splits across threads without changing a byte.
pub fn collapse(nodes: &[BvhNode]) -> Vec<WideNode> {
    if nodes.is_empty() {
        return Vec::new();
    }
    let planned = plan(nodes);
    let threads = if planned.len() >= PARALLEL_ENCODE_THRESHOLD {
        std::thread::available_parallelism().map_or(1, usize::from)
    } else {
        1
    };
    encode(nodes, &planned, threads)
}

/// Wide nodes below this count are encoded on the current thread: a thread's start
/// costs more than encoding them.
const PARALLEL_ENCODE_THRESHOLD: usize = 8192;

/// A wide node chosen but not yet encoded.
#[derive(Debug, Clone, Copy)]
struct Planned {
    /// The binary node it stands for (its box is the wide node's).
    binary: u32,
    /// Its children as binary nodes, in slot order; `len` of them are used.
    members: [u32; WIDTH],
    /// Number of children.
    len: u32,
    /// The wide index of its first inner child; the others follow in slot order.
    first_child: u32,
}

/// A candidate child while a wide node is being filled.
#[derive(Debug, Clone, Copy)]
struct Member {
    /// The binary node.
    node: u32,
    /// Its binary depth below the wide node's binary node.
    depth: u32,
    /// Its box's half area (in `f64`), the tie-break between equally deep nodes.
    half_area: f64,
}

impl Member {
    fn new(nodes: &[BvhNode], node: u32, depth: u32) -> Self {
        let n = &nodes[node as usize];
        let e = [0, 1, 2].map(|a| f64::from(n.max[a]) - f64::from(n.min[a]));
        Self {
            node,
            depth,
            half_area: e[0] * e[1] + e[1] * e[2] + e[2] * e[0],
        }
    }
}

/// The children of the wide node that stands for binary node `binary`, in slot order
/// (the module's greedy rule): its binary children, then repeatedly the inner member
/// of smallest depth (the larger box first, the earlier slot at a tie) replaced by
/// its two children, the last member moving into its slot, until there are
/// [`WIDTH`] or only leaves. A leaf (a tree that is one leaf) is its own only child.
fn choose_members(nodes: &[BvhNode], binary: u32) -> ([u32; WIDTH], usize) {
    let node = &nodes[binary as usize];
    let mut members = [Member {
        node: 0,
        depth: 0,
        half_area: 0.0,
    }; WIDTH];
    let mut len;
    if node.is_leaf() {
        members[0] = Member::new(nodes, binary, 0);
        len = 1;
    } else {
        members[0] = Member::new(nodes, node.first, 1);
        members[1] = Member::new(nodes, node.first + 1, 1);
        len = 2;
    }
    while len < WIDTH {
        let mut open: Option<usize> = None;
        for (i, m) in members[..len].iter().enumerate() {
            if nodes[m.node as usize].is_leaf() {
                continue;
            }
            let better = open.is_none_or(|o| {
                let best = &members[o];
                m.depth
                    .cmp(&best.depth)
                    .then(best.half_area.total_cmp(&m.half_area))
                    .is_lt()
            });
            if better {
                open = Some(i);
            }
        }
        let Some(i) = open else { break };
        let opened = members[i];
        // `Vec::swap_remove`: the last member takes the opened one's slot.
        members[i] = members[len - 1];
        let first = nodes[opened.node as usize].first;
        members[len - 1] = Member::new(nodes, first, opened.depth + 1);
        members[len] = Member::new(nodes, first + 1, opened.depth + 1);
        len += 1;
    }
    (members.map(|m| m.node), len)
}

/// Chooses every wide node's children and numbers the wide nodes: a wide node's inner
/// children get consecutive indices when it is taken from the stack of pending nodes,
/// and the last of them is taken first (the order the tracers' buffers have always
/// had).
fn plan(nodes: &[BvhNode]) -> Vec<Planned> {
    let unplanned = Planned {
        binary: 0,
        members: [0; WIDTH],
        len: 0,
        first_child: 0,
    };
    let mut planned = Vec::with_capacity(nodes.len() / 4 + 1);
    planned.push(unplanned);
    // (binary node, its wide node's index)
    let mut pending = vec![(0u32, 0usize)];
    while let Some((binary, slot)) = pending.pop() {
        let (members, len) = choose_members(nodes, binary);
        let first_child = planned.len();
        for &member in &members[..len] {
            if !nodes[member as usize].is_leaf() {
                pending.push((member, planned.len()));
                planned.push(unplanned);
            }
        }
        planned[slot] = Planned {
            binary,
            members,
            len: len as u32,
            first_child: u32::try_from(first_child).unwrap_or(CHILD_INDEX_MASK),
        };
    }
    planned
}

/// Encodes the planned wide nodes, `threads` contiguous runs of them at once.
fn encode(nodes: &[BvhNode], planned: &[Planned], threads: usize) -> Vec<WideNode> {
    let mut wide = vec![WideNode::zeroed(); planned.len()];
    let chunk = planned.len().div_ceil(threads.max(1)).max(1);
    std::thread::scope(|scope| {
        let mut runs = wide.chunks_mut(chunk).zip(planned.chunks(chunk));
        // The first run is encoded here, the others on threads of their own.
        let first = runs.next();
        for (out, plans) in runs {
            scope.spawn(move || encode_run(nodes, plans, out));
        }
        if let Some((out, plans)) = first {
            encode_run(nodes, plans, out);
        }
    });
    wide
}

/// Encodes `plans` into `out` (as long).
fn encode_run(nodes: &[BvhNode], plans: &[Planned], out: &mut [WideNode]) {
    for (plan, slot) in plans.iter().zip(out) {
        *slot = encode_one(nodes, plan);
    }
}

/// The wide node `plan` describes.
fn encode_one(nodes: &[BvhNode], plan: &Planned) -> WideNode {
    let aabb = |n: &BvhNode| Aabb32 {
        min: n.min,
        max: n.max,
    };
    let mut children = [(WideChild::Empty, Aabb32::EMPTY); WIDTH];
    let mut next_inner = plan.first_child;
    for (slot, &member) in plan.members[..plan.len as usize].iter().enumerate() {
        let child = &nodes[member as usize];
        let named = if child.is_leaf() {
            WideChild::Leaf {
                first: child.first,
                count: child.count,
            }
        } else {
            next_inner += 1;
            WideChild::Node(next_inner - 1)
        };
        children[slot] = (named, aabb(child));
    }
    WideNode::new(
        aabb(&nodes[plan.binary as usize]),
        &children[..plan.len as usize],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::{BuildMethod, Bvh, MAX_LEAF_PRIMITIVES};
    use crate::accel::geometry::{PrimKind, PrimRef};
    use glam::DVec3;

    fn contains(outer: &Aabb32, inner: &Aabb32) -> bool {
        (0..3).all(|a| outer.min[a] <= inner.min[a] && outer.max[a] >= inner.max[a])
    }

    /// Every primitive is reached exactly once, through boxes that contain it, within
    /// the depth bound.
    fn check(wide: &[WideNode], bvh: &Bvh, boxes: &[(PrimRef, Aabb32)]) {
        let mut seen = vec![0u32; boxes.len()];
        let mut pending = vec![(0u32, 1u32)];
        while let Some((index, depth)) = pending.pop() {
            assert!(depth <= MAX_WIDE_DEPTH, "depth {depth}");
            let node = &wide[index as usize];
            for slot in 0..WIDTH {
                let b = node.child_box(slot);
                match node.child(slot) {
                    WideChild::Empty => {}
                    WideChild::Node(child) => {
                        let inner = &wide[child as usize];
                        let inner_box = Aabb32 {
                            min: inner.origin,
                            max: inner.origin,
                        };
                        assert!(
                            contains(&b, &inner_box),
                            "node {child} starts outside its box"
                        );
                        pending.push((child, depth + 1));
                    }
                    WideChild::Leaf { first, count } => {
                        assert!((1..=MAX_LEAF_PRIMITIVES).contains(&count));
                        for p in &bvh.prims[first as usize..(first + count) as usize] {
                            seen[p.index()] += 1;
                            assert!(contains(&b, &boxes[p.index()].1), "slot {slot} of {index}");
                        }
                    }
                }
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
    }

    fn boxes(n: usize, scale: f64, offset: f64) -> Vec<(PrimRef, Aabb32)> {
        (0..n)
            .map(|i| {
                let c = DVec3::new(
                    ((i * 7919) % 1000) as f64,
                    ((i * 104_729) % 997) as f64,
                    (i % 13) as f64,
                ) * scale
                    + offset;
                (
                    PrimRef::new(PrimKind::Triangle, i as u32),
                    Aabb32::around(c - 0.4 * scale, c + 0.4 * scale),
                )
            })
            .collect()
    }

    /// Boxes of many sizes scattered over several orders of magnitude (a fixed
    /// pseudo-random sequence).
    fn scattered_boxes(n: usize) -> Vec<(PrimRef, Aabb32)> {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|i| {
                let scale = 10f64.powf(next() * 6.0 - 3.0);
                let c = DVec3::new(next(), next(), next()) * 1000.0 - 500.0;
                let half = DVec3::new(next(), next(), next()) * scale;
                (
                    PrimRef::new(PrimKind::Triangle, i as u32),
                    Aabb32::around(c - half, c + half),
                )
            })
            .collect()
    }

    /// The collapse as it was first written, one node at a time with the scalar
    /// quantization (`log2`, division, `floor` and `ceil`): the reference the planned,
    /// parallel and SIMD collapse must match bit for bit.
    fn reference_collapse(nodes: &[BvhNode]) -> Vec<WideNode> {
        fn exponent(lo: f32, hi: f32) -> u32 {
            let extent = f64::from(hi) - f64::from(lo);
            let mut biased = if extent > 0.0 {
                ((extent / 255.0).log2().ceil() as i64 + 127).clamp(1, 254) as u32
            } else {
                1
            };
            while biased > 1 && dequantize(lo, step_of(biased - 1), 255) >= hi {
                biased -= 1;
            }
            while biased < 254 && dequantize(lo, step_of(biased), 255) < hi {
                biased += 1;
            }
            biased
        }
        fn down(origin: f32, step: f32, x: f32) -> u32 {
            let e = ((f64::from(x) - f64::from(origin)) / f64::from(step)).floor();
            let mut q = e.clamp(0.0, 255.0) as u32;
            while q > 0 && dequantize(origin, step, q) > x {
                q -= 1;
            }
            while q < 255 && dequantize(origin, step, q + 1) <= x {
                q += 1;
            }
            q
        }
        fn up(origin: f32, step: f32, x: f32) -> u32 {
            let e = ((f64::from(x) - f64::from(origin)) / f64::from(step)).ceil();
            let mut q = e.clamp(0.0, 255.0) as u32;
            while q < 255 && dequantize(origin, step, q) < x {
                q += 1;
            }
            while q > 0 && dequantize(origin, step, q - 1) >= x {
                q -= 1;
            }
            q
        }
        let encode = |bounds: Aabb32, children: &[(WideChild, Aabb32)]| {
            let origin = bounds.min.map(normal_or_zero_below);
            let mut node = WideNode {
                origin,
                exponents: 0,
                low: [0; 3],
                spare_low: 0,
                high: [0; 3],
                spare_high: 0,
                children: [EMPTY_CHILD; WIDTH],
            };
            for (axis, &start) in origin.iter().enumerate() {
                let biased = exponent(start, bounds.max[axis]);
                node.exponents |= biased << (8 * axis);
                let step = step_of(biased);
                for (slot, (_, aabb)) in children.iter().enumerate() {
                    node.low[axis] |= down(start, step, aabb.min[axis]) << (8 * slot);
                    node.high[axis] |= up(start, step, aabb.max[axis]) << (8 * slot);
                }
                for slot in children.len()..WIDTH {
                    node.low[axis] |= 0xff << (8 * slot);
                }
            }
            for (slot, (child, _)) in children.iter().enumerate() {
                node.children[slot] = child.word();
            }
            node
        };
        let aabb = |n: &BvhNode| Aabb32 {
            min: n.min,
            max: n.max,
        };
        let half_area = |n: &BvhNode| {
            let e = [0, 1, 2].map(|a| f64::from(n.max[a]) - f64::from(n.min[a]));
            e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
        };
        let mut wide = vec![WideNode::zeroed()];
        let mut pending = vec![(0usize, 0usize)];
        while let Some((binary, slot)) = pending.pop() {
            let node = &nodes[binary];
            let mut members: Vec<(usize, u32)> = if node.is_leaf() {
                vec![(binary, 0)]
            } else {
                vec![(node.first as usize, 1), (node.first as usize + 1, 1)]
            };
            while members.len() < WIDTH {
                let open = members
                    .iter()
                    .enumerate()
                    .filter(|(_, (n, _))| !nodes[*n].is_leaf())
                    .min_by(|(_, (a, da)), (_, (b, db))| {
                        da.cmp(db)
                            .then(half_area(&nodes[*b]).total_cmp(&half_area(&nodes[*a])))
                    })
                    .map(|(i, _)| i);
                let Some(i) = open else { break };
                let (n, depth) = members.swap_remove(i);
                let first = nodes[n].first as usize;
                members.push((first, depth + 1));
                members.push((first + 1, depth + 1));
            }
            let children: Vec<(WideChild, Aabb32)> = members
                .iter()
                .map(|&(n, _)| {
                    let child = &nodes[n];
                    let named = if child.is_leaf() {
                        WideChild::Leaf {
                            first: child.first,
                            count: child.count,
                        }
                    } else {
                        wide.push(WideNode::zeroed());
                        pending.push((n, wide.len() - 1));
                        WideChild::Node((wide.len() - 1) as u32)
                    };
                    (named, aabb(child))
                })
                .collect();
            wide[slot] = encode(aabb(node), &children);
        }
        wide
    }

    #[test]
    fn the_collapse_matches_the_one_pass_scalar_collapse_bit_for_bit() {
        for prims in [
            scattered_boxes(40_000),
            boxes(20_000, 1e-6, 1e3),
            boxes(3000, 1e12, -1e15),
            boxes(5, 1.0, 0.0),
        ] {
            for method in [BuildMethod::Sah, BuildMethod::MedianSplit] {
                let bvh = Bvh::build(&prims, method);
                let reference = reference_collapse(&bvh.nodes);
                assert_eq!(bvh.wide, reference);
                // The runs split across threads and encoded on one agree too.
                let planned = plan(&bvh.nodes);
                assert_eq!(encode(&bvh.nodes, &planned, 1), reference);
                assert_eq!(encode(&bvh.nodes, &planned, 3), reference);
                check(&bvh.wide, &bvh, &prims);
            }
        }
    }

    #[test]
    fn every_primitive_is_reached_once_through_boxes_that_contain_it() {
        for (n, scale, offset) in [
            (1, 1.0, 0.0),
            (3, 1.0, 0.0),
            (5, 1.0, 0.0),
            (3000, 0.1, 0.0),
            (3000, 1e-6, 1e3),
            (3000, 1e12, -1e15),
            (2000, 1e-30, 0.0),
        ] {
            let prims = boxes(n, scale, offset);
            let bvh = Bvh::build(&prims, BuildMethod::Sah);
            check(&collapse(&bvh.nodes), &bvh, &prims);
        }
        assert!(collapse(&[]).is_empty());
    }

    #[test]
    fn identical_boxes_collapse_within_the_depth_bound() {
        let one = Aabb32::around(DVec3::ZERO, DVec3::ONE);
        let prims: Vec<_> = (0..20_000)
            .map(|i| (PrimRef::new(PrimKind::Triangle, i), one))
            .collect();
        let bvh = Bvh::build(&prims, BuildMethod::MedianSplit);
        check(&collapse(&bvh.nodes), &bvh, &prims);
    }

    #[test]
    fn every_binary_inner_node_is_absorbed_once_and_wide_nodes_hold_near_three_children() {
        let prims = boxes(10_000, 0.1, 0.0);
        let bvh = Bvh::build(&prims, BuildMethod::Sah);
        let wide = collapse(&bvh.nodes);
        let inner = bvh.nodes.len() - bvh.stats.leaves;
        // A wide node of k children stands for k - 1 binary inner nodes.
        let children: usize = wide
            .iter()
            .map(|n| {
                (0..WIDTH)
                    .filter(|&s| n.child(s) != WideChild::Empty)
                    .count()
            })
            .sum();
        assert_eq!(children - wide.len(), inner);
        // With leaves of two, the parents of two leaves deep in the tree become wide
        // nodes of two children, so the mean is below four: 2.86 for this tree.
        let mean = children as f64 / wide.len() as f64;
        assert!(mean >= 2.75, "{mean} children per wide node");
    }

    #[test]
    fn child_words_round_trip() {
        for child in [
            WideChild::Empty,
            WideChild::Node(0),
            WideChild::Node(CHILD_INDEX_MASK),
            WideChild::Leaf { first: 7, count: 4 },
            WideChild::Leaf {
                first: CHILD_INDEX_MASK,
                count: 1,
            },
        ] {
            assert_eq!(WideChild::from_word(child.word()), child);
        }
    }

    #[test]
    fn quantized_bounds_are_tight_within_one_step() {
        let node = WideNode::new(
            Aabb32 {
                min: [0.0; 3],
                max: [255.0; 3],
            },
            &[(
                WideChild::Node(1),
                Aabb32 {
                    min: [10.5; 3],
                    max: [20.25; 3],
                },
            )],
        );
        let b = node.child_box(0);
        assert_eq!(b.min, [10.0; 3]);
        assert_eq!(b.max, [21.0; 3]);
    }
}
