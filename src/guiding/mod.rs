//! Path guiding for direct light: an SD-tree (Müller, Gross & Novák 2017, "Practical Path Guiding for Efficient
//! Light-Transport Simulation") that learns where the incident radiance `L_i = L_e V` comes from at the points the
//! camera sees, from the directions evaluated there, and gives a density over the sphere to sample it with.
//!
//! - [`STree`]: a binary tree over the scene's box (cycling axes); each leaf owns a [`DTree`], a quadtree over the
//!   sphere in equal-area coordinates whose energies are sums of `L_i / p` (so its density tends to ∝ L_i).
//! - [`Guide`]: the frozen tree a pass samples from (read-only during the pass).
//! - [`Training`]: iteration k records the samples `2^k − 1 .. 2^(k+1) − 1` of every pixel into the sums of a
//!   tree shaped by iteration k − 1's, then builds the next guide from them; after the training budget the guide
//!   is frozen. Sums are fixed-point integers, so the guide is the same whatever the order of the records (any
//!   thread count, any split into passes).
//!
//! Records are splatted with Müller's box filters, spatially (a jittered position within the leaf's box) and
//! over directions (a square as wide as the record's quadtree leaf), and each leaf learns its mixture weights
//! (see [`mixture`]). Each quadtree learns its light as seen from its leaf's centre, so that every point of the
//! leaf aims at the same points ([`Anchor`]: parallax-aware guiding), and learns them where its rays converge:
//! in the plane of the light, or of the opening the light comes through ([`focal_plane`]), fitted at each build
//! to the iteration's rays. Written from the papers (whose code is GPL-3: none is copied). The guide learns light
//! only, so a change of camera or material keeps it.

mod dtree;
mod focus;
mod mixture;
mod parallax;
mod shape;
mod stree;
mod training;

pub use dtree::{DTree, Sums, dir_to_square, square_to_dir};
pub use focus::focal_plane;
pub use mixture::{CANDIDATES, DEFAULT_WEIGHTS, MixtureSample, Moments, candidate};
pub use parallax::Anchor;
pub use shape::Shape;
pub use stree::{LeafHint, STree};
pub use training::{Found, GuideRecord, GuideSettings, IterationReport, Training, TrainingStatus};

use glam::Vec3;

/// A frozen SD-tree: where each point's quadtree is, and the quadtrees.
#[derive(Clone, Debug, PartialEq)]
pub struct Guide {
    pub stree: STree,
    /// Per spatial leaf: the quadtree.
    pub dtrees: Vec<DTree>,
    /// Per spatial leaf: the mixture weights (c_g, c_l, c_b) `guided` samples with there.
    pub weights: Vec<[f32; 3]>,
    /// Per spatial leaf: the centre of its box, the anchor of the quadtree it records into (see [`Anchor`]).
    pub centres: Vec<Vec3>,
    /// Which scene's light it learned: [`light_fingerprint`] of that scene.
    pub fingerprint: u64,
}

impl Guide {
    /// A guide of the given leaves' quadtrees, with the default mixture weights everywhere.
    pub fn new(stree: STree, dtrees: Vec<DTree>, fingerprint: u64) -> Self {
        let weights = vec![DEFAULT_WEIGHTS; dtrees.len()];
        let centres = stree.leaf_centres();
        Self { stree, dtrees, weights, centres, fingerprint }
    }

    /// A guide with no energy (no density anywhere) over the box `lo..hi`.
    pub fn empty(lo: Vec3, hi: Vec3, fingerprint: u64) -> Self {
        Self::new(STree::new(lo, hi), vec![DTree::default()], fingerprint)
    }

    /// The quadtree of the leaf holding `p`.
    #[inline]
    pub fn dtree(&self, p: Vec3) -> &DTree {
        &self.dtrees[self.stree.leaf(p) as usize]
    }

    /// The quadtree and the mixture weights of the leaf holding `p`.
    #[inline]
    pub fn leaf(&self, p: Vec3) -> (&DTree, [f32; 3]) {
        let leaf = self.stree.leaf(p) as usize;
        (&self.dtrees[leaf], self.weights[leaf])
    }

    /// [`Guide::leaf`] through a hint (see [`STree::leaf_near`]): the same leaf.
    #[inline]
    pub fn leaf_near(&self, p: Vec3, hint: &mut Option<LeafHint>) -> (&DTree, [f32; 3]) {
        let leaf = self.stree.leaf_near(p, hint) as usize;
        (&self.dtrees[leaf], self.weights[leaf])
    }

    /// Quadtree nodes over all leaves.
    pub fn dtree_nodes(&self) -> usize {
        self.dtrees.iter().map(|d| d.shape().nodes()).sum()
    }

    /// Bytes the guide occupies: the quadtrees, the spatial nodes, and each leaf's weights, anchor and focus.
    pub fn bytes(&self) -> usize {
        let per_leaf = std::mem::size_of::<[f32; 3]>() + std::mem::size_of::<Vec3>();
        self.dtrees.iter().map(DTree::bytes).sum::<usize>() + self.stree.nodes() * 8 + self.weights.len() * per_leaf
    }

    /// Whether any leaf has a density.
    pub fn is_usable(&self) -> bool {
        self.dtrees.iter().any(DTree::is_usable)
    }
}

/// A hash of what a guide learns: the triangles' positions and each triangle's emitted radiance. Equal for a
/// scene whose camera or non-emitting materials changed; different when geometry or light did.
pub fn light_fingerprint(scene: &crate::scene::Scene) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for (i, t) in scene.triangles.iter().enumerate() {
        for v in t.v {
            v.to_array().map(f32::to_bits).hash(&mut h);
        }
        let n = t.n;
        scene.emitted(i as u32, n).to_array().map(f32::to_bits).hash(&mut h);
        scene.emitted(i as u32, -n).to_array().map(f32::to_bits).hash(&mut h);
    }
    h.finish()
}
