//! The spatial binary tree of Müller et al. 2017 (§3.1): the scene's bounding box made a cube, halved again and
//! again along x, y, z in turn; each leaf owns a directional quadtree. A leaf that received more than
//! `c √(2^k)` records in iteration k is split (the paper's c = 12 000; see [`super::GuideSettings`]) and both
//! halves start from a copy of its quadtree.

use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
enum SNode {
    /// Halves at the node's middle along the axis `depth % 3`: [lower, upper].
    Inner([u32; 2]),
    /// Index of the leaf.
    Leaf(u32),
}

/// The spatial tree: which leaf holds a point.
#[derive(Clone, Debug, PartialEq)]
pub struct STree {
    /// The cube's lower corner and side.
    origin: Vec3,
    side: f32,
    nodes: Vec<SNode>,
    leaves: usize,
}

/// A leaf and its box, in the tree's unit cube (see [`STree::leaf_near`]).
#[derive(Clone, Copy, Debug)]
pub struct LeafHint {
    leaf: u32,
    lo: Vec3,
    hi: Vec3,
}

impl STree {
    /// One leaf over the cube around the box `lo..hi` (enlarged by 1% so that points on its faces are inside).
    pub fn new(lo: Vec3, hi: Vec3) -> Self {
        let size = (hi - lo).max_element().max(1e-6) * 1.01;
        let centre = (lo + hi) * 0.5;
        Self { origin: centre - Vec3::splat(size * 0.5), side: size, nodes: vec![SNode::Leaf(0)], leaves: 1 }
    }

    pub fn leaves(&self) -> usize {
        self.leaves
    }

    pub fn nodes(&self) -> usize {
        self.nodes.len()
    }

    /// The leaf holding `p` (a point outside the cube: the leaf of the nearest point inside).
    #[inline]
    pub fn leaf(&self, p: Vec3) -> u32 {
        self.leaf_extent(p).0
    }

    /// The leaf holding `p` and its box's size.
    #[inline]
    pub fn leaf_extent(&self, p: Vec3) -> (u32, Vec3) {
        let mut x = ((p - self.origin) / self.side).clamp(Vec3::ZERO, Vec3::splat(1.0 - f32::EPSILON));
        let (mut node, mut axis, mut size) = (0usize, 0usize, Vec3::splat(self.side));
        loop {
            match self.nodes[node] {
                SNode::Leaf(leaf) => return (leaf, size),
                SNode::Inner(children) => {
                    let upper = x[axis] >= 0.5;
                    x[axis] = if upper { x[axis] * 2.0 - 1.0 } else { x[axis] * 2.0 };
                    size[axis] *= 0.5;
                    node = children[upper as usize] as usize;
                    axis = (axis + 1) % 3;
                }
            }
        }
    }

    /// [`STree::leaf_near`] and the size of the leaf's box (as [`STree::leaf_extent`] gives it).
    #[inline]
    pub fn leaf_extent_near(&self, p: Vec3, hint: &mut Option<LeafHint>) -> (u32, Vec3) {
        let leaf = self.leaf_near(p, hint);
        (leaf, hint.map_or(Vec3::splat(self.side), |h| (h.hi - h.lo) * self.side))
    }

    /// [`STree::leaf`], remembering the leaf's box in `hint`: a point in the box of the hint's leaf is in that
    /// leaf, found without a descent (the samples of one pixel mostly share a leaf). The descent halves `x` at
    /// dyadic thresholds, exactly, so the box test gives the descent's answer bit for bit.
    #[inline]
    pub fn leaf_near(&self, p: Vec3, hint: &mut Option<LeafHint>) -> u32 {
        let x = ((p - self.origin) / self.side).clamp(Vec3::ZERO, Vec3::splat(1.0 - f32::EPSILON));
        if let Some(h) = hint
            && x.cmpge(h.lo).all()
            && x.cmplt(h.hi).all()
        {
            return h.leaf;
        }
        let (mut node, mut axis) = (0usize, 0usize);
        let (mut lo, mut size) = (Vec3::ZERO, Vec3::ONE);
        loop {
            match self.nodes[node] {
                SNode::Leaf(leaf) => {
                    *hint = Some(LeafHint { leaf, lo, hi: lo + size });
                    return leaf;
                }
                SNode::Inner(children) => {
                    size[axis] *= 0.5;
                    let upper = x[axis] >= lo[axis] + size[axis];
                    if upper {
                        lo[axis] += size[axis];
                    }
                    node = children[upper as usize] as usize;
                    axis = (axis + 1) % 3;
                }
            }
        }
    }

    /// The centre of every leaf's box, by leaf (the anchors of their quadtrees: see [`super::Anchor`]).
    pub fn leaf_centres(&self) -> Vec<Vec3> {
        let mut centres = vec![Vec3::ZERO; self.leaves];
        let mut stack = vec![(0usize, 0usize, Vec3::ZERO, Vec3::ONE)];
        while let Some((node, axis, lo, size)) = stack.pop() {
            match self.nodes[node] {
                SNode::Leaf(leaf) => centres[leaf as usize] = self.origin + (lo + size * 0.5) * self.side,
                SNode::Inner(children) => {
                    let mut half = size;
                    half[axis] *= 0.5;
                    let mut upper = lo;
                    upper[axis] += half[axis];
                    stack.push((children[0] as usize, (axis + 1) % 3, lo, half));
                    stack.push((children[1] as usize, (axis + 1) % 3, upper, half));
                }
            }
        }
        centres
    }

    /// Splits every leaf whose count exceeds `threshold`, and each half again while half the count exceeds it
    /// (Müller's halving of the statistical weight), keeping the tree at most `max_depth` levels deep. Returns,
    /// per new leaf, the old leaf it came from (whose quadtree it starts from).
    pub fn split(&mut self, counts: &[u64], threshold: f64, max_depth: usize) -> Vec<u32> {
        let mut parents = Vec::new();
        let mut nodes = Vec::with_capacity(self.nodes.len());
        let split = |leaf: u32, halvings: usize, depth: usize| {
            depth + 1 < max_depth && counts[leaf as usize] as f64 / (halvings as f64).exp2() > threshold
        };
        self.rebuild(0, 0, &mut nodes, &mut parents, &split);
        self.nodes = nodes;
        self.leaves = parents.len();
        parents
    }

    /// Copies the subtree at `node` (at `depth`) into `out`, splitting its leaves as `split` says.
    fn rebuild(
        &self,
        node: usize,
        depth: usize,
        out: &mut Vec<SNode>,
        parents: &mut Vec<u32>,
        split: &dyn Fn(u32, usize, usize) -> bool,
    ) -> u32 {
        let index = out.len();
        out.push(SNode::Leaf(0));
        out[index] = match self.nodes[node] {
            SNode::Inner(children) => {
                let a = self.rebuild(children[0] as usize, depth + 1, out, parents, split);
                let b = self.rebuild(children[1] as usize, depth + 1, out, parents, split);
                SNode::Inner([a, b])
            }
            SNode::Leaf(leaf) => split_leaf(leaf, 0, depth, out, parents, split),
        };
        index as u32
    }
}

/// The node replacing old leaf `leaf`, halved `halvings` times so far, at `depth`.
fn split_leaf(
    leaf: u32,
    halvings: usize,
    depth: usize,
    out: &mut Vec<SNode>,
    parents: &mut Vec<u32>,
    split: &dyn Fn(u32, usize, usize) -> bool,
) -> SNode {
    if split(leaf, halvings, depth) {
        let mut children = [0u32; 2];
        for child in &mut children {
            let index = out.len();
            out.push(SNode::Leaf(0));
            out[index] = split_leaf(leaf, halvings + 1, depth + 1, out, parents, split);
            *child = index as u32;
        }
        SNode::Inner(children)
    } else {
        parents.push(leaf);
        SNode::Leaf(parents.len() as u32 - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_find_their_leaves_after_splits() {
        let mut tree = STree::new(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0));
        assert_eq!(tree.leaf(Vec3::new(1.9, 0.1, 0.1)), 0);
        // One leaf with 1000 records, threshold 100: 1000, 500, 250 and 125 are split, 62.5 is not.
        let parents = tree.split(&[1000], 100.0, 20);
        assert_eq!(parents, vec![0; 16]);
        assert_eq!(tree.leaves(), 16);
        // Eight cubes of a side a half: corners of the cube [−0.01, 2.01] × [−0.51, 1.51] × [−0.51, 1.51].
        let mut seen = std::collections::BTreeSet::new();
        for i in 0..2 {
            for j in 0..2 {
                for k in 0..2 {
                    let p = Vec3::new(0.5 + i as f32, 0.0 + j as f32, 0.0 + k as f32);
                    seen.insert(tree.leaf(p));
                }
            }
        }
        assert_eq!(seen.len(), 8, "each octant its own leaf");
        // Split only leaf 3 further: 300 and 150 are split, 75 is not.
        let mut counts = vec![0; 16];
        counts[3] = 300;
        let parents = tree.split(&counts, 100.0, 20);
        assert_eq!(tree.leaves(), 19);
        assert_eq!(parents.iter().filter(|&&p| p == 3).count(), 4);
        assert!(parents.windows(2).all(|w| w[0] <= w[1]), "new leaves keep the old leaves' order");
        // Every leaf's centre lies in that leaf, and in no other.
        let centres = tree.leaf_centres();
        assert_eq!(centres.len(), tree.leaves());
        for (leaf, c) in centres.iter().enumerate() {
            assert_eq!(tree.leaf(*c), leaf as u32, "centre {c}");
        }
    }

    /// A hint gives the leaf a descent gives, for points inside, on and beyond its box's faces, after splits
    /// that leave leaves of many depths (down to 2⁻¹⁵ of the side on an axis).
    #[test]
    fn a_hinted_lookup_finds_the_leaf_a_descent_finds() {
        let mut tree = STree::new(Vec3::new(-3.0, 0.5, 2.0), Vec3::new(4.0, 1.0, 3.0));
        for round in 0..6u64 {
            let counts: Vec<u64> = (0..tree.leaves() as u64).map(|l| (l * 7919 + round * 104_729) % 5000).collect();
            tree.split(&counts, 400.0, 46);
        }
        assert!(tree.leaves() > 500, "{} leaves: the test checks too little", tree.leaves());
        let (lo, side) = (tree.origin, tree.side);
        let mut hint = None;
        let mut rng = crate::math::SampleRng::new(3, 1, 4);
        let mut reused = 0;
        let mut centre = lo;
        for i in 0..200_000 {
            // Clusters of eight nearby points (as a pixel's samples), some reaching outside the cube, and dyadic
            // grid points (on the faces of boxes).
            let mut unit = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
            if i % 8 == 0 {
                centre = lo + Vec3::splat(side) * (unit() * 1.2 - 0.1);
            }
            let p = if i % 8 == 7 {
                lo + Vec3::splat(side) * ((unit() * 64.0).floor() / 64.0)
            } else {
                centre + unit() * 1e-3
            };
            let had = hint.map(|h: LeafHint| h.leaf);
            let near = tree.leaf_near(p, &mut hint);
            assert_eq!(near, tree.leaf(p), "point {p}");
            reused += (had == Some(near)) as u32;
        }
        assert!(reused > 10_000, "the hint was used only {reused} times");
    }

    #[test]
    fn the_depth_limit_holds() {
        let mut tree = STree::new(Vec3::ZERO, Vec3::ONE);
        tree.split(&[u64::MAX], 1.0, 6);
        assert_eq!(tree.leaves(), 32, "at most 6 levels: 5 splits");
    }
}
