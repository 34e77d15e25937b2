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
    }

    #[test]
    fn the_depth_limit_holds() {
        let mut tree = STree::new(Vec3::ZERO, Vec3::ONE);
        tree.split(&[u64::MAX], 1.0, 6);
        assert_eq!(tree.leaves(), 32, "at most 6 levels: 5 splits");
    }
}
