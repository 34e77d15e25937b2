//! The shape of a directional quadtree (Müller et al. 2017, §3.2) over the square [0, 1)² of the equal-area
//! sphere parametrisation: each node splits its square into four quadrants, each a leaf or another node. The
//! density that samples ([`super::DTree`]) and the sums that record ([`super::Sums`]) share it.

use glam::{DVec2, Vec2};

/// Quadrant q of a node's square: bit 0 is the right half (x ≥ ½), bit 1 the upper half (y ≥ ½).
#[inline]
pub(super) fn quadrant(s: DVec2) -> (usize, DVec2) {
    let (right, up) = (s.x >= 0.5, s.y >= 0.5);
    let q = right as usize | (up as usize) << 1;
    let local = DVec2::new(if right { s.x - 0.5 } else { s.x }, if up { s.y - 0.5 } else { s.y }) * 2.0;
    (q, local.min(DVec2::splat(1.0 - f64::EPSILON)))
}

/// One node: its four quadrants' children (0: the quadrant is a leaf; the root, index 0, is no one's child).
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct Node {
    pub(super) children: [u32; 4],
}

/// The shape of a quadtree, shared by the density that samples and the sums that record.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    pub(super) nodes: Vec<Node>,
}

impl Default for Shape {
    /// The root alone: four quadrants.
    fn default() -> Self {
        Self { nodes: vec![Node::default()] }
    }
}

impl Shape {
    /// Every leaf's square: (lower corner, side), depth first.
    pub fn leaves(&self) -> Vec<(Vec2, f32)> {
        let mut out = Vec::new();
        let mut stack = vec![(0usize, Vec2::ZERO, 1.0f32)];
        while let Some((node, corner, side)) = stack.pop() {
            let half = side * 0.5;
            for q in 0..4 {
                let c = corner + Vec2::new((q & 1) as f32, (q >> 1) as f32) * half;
                match self.nodes[node].children[q] {
                    0 => out.push((c, half)),
                    child => stack.push((child as usize, c, half)),
                }
            }
        }
        out
    }

    /// The leaf holding square point `s`: (node, quadrant).
    #[inline]
    pub(super) fn leaf(&self, s: Vec2) -> (usize, usize) {
        let (mut node, mut s) = (0usize, s.as_dvec2());
        loop {
            let (q, local) = quadrant(s);
            match self.nodes[node].children[q] {
                0 => return (node, q),
                child => (node, s) = (child as usize, local),
            }
        }
    }

    pub fn nodes(&self) -> usize {
        self.nodes.len()
    }

    /// The side of the leaf holding square point `s`.
    pub fn leaf_side(&self, s: Vec2) -> f32 {
        let (mut node, mut s, mut side) = (0usize, s.as_dvec2(), 0.5f32);
        loop {
            let (q, local) = quadrant(s);
            match self.nodes[node].children[q] {
                0 => return side,
                child => (node, s, side) = (child as usize, local, side * 0.5),
            }
        }
    }

    pub fn depth(&self) -> usize {
        fn depth(shape: &Shape, node: usize) -> usize {
            1 + shape.nodes[node]
                .children
                .iter()
                .filter(|&&c| c != 0)
                .map(|&c| depth(shape, c as usize))
                .max()
                .unwrap_or(0)
        }
        depth(self, 0)
    }
    /// A shape refined uniformly to `depth` levels (4^depth leaves), for tests and synthetic guides.
    pub fn uniform(depth: usize) -> Self {
        let mut shape = Shape::default();
        let mut level = vec![0usize];
        for _ in 1..depth {
            let mut next = Vec::new();
            for &node in &level {
                for q in 0..4 {
                    let child = shape.nodes.len();
                    shape.nodes.push(Node::default());
                    shape.nodes[node].children[q] = child as u32;
                    next.push(child);
                }
            }
            level = next;
        }
        shape
    }

    /// A shape refined only along the path to the square point `s`, `depth` levels deep.
    pub fn towards(s: Vec2, depth: usize) -> Self {
        let mut shape = Shape::default();
        let (mut node, mut s) = (0usize, s.as_dvec2());
        for _ in 1..depth {
            let (q, local) = quadrant(s);
            let child = shape.nodes.len();
            shape.nodes.push(Node::default());
            shape.nodes[node].children[q] = child as u32;
            (node, s) = (child, local);
        }
        shape
    }
}
