//! The directional quadtree of Müller, Gross & Novák 2017 ("Practical Path Guiding", §3.2): a piecewise-constant
//! density over the whole sphere, a quadtree over the square [0, 1)² of the equal-area parametrisation
//!
//! `s = ((cos θ + 1)/2, φ/2π)`,  dω = 4π ds  (the square's area 1 is the sphere's 4π sr),
//!
//! so a cell's density is its share of the energy divided by its solid angle. Each node splits its square into
//! four quadrants; a quadrant is a leaf or another node. Drawing descends from the root, choosing a quadrant with
//! probability proportional to its energy, then a uniform point in the leaf reached:
//!
//! `p(ω) = (1/4π) Π_levels 4 E_q / Σ_q' E_q'`.
//!
//! The energies are sums of `L_i / p` over the directions recorded in each cell: Monte Carlo estimates of
//! ∫_cell L_i dω, so p(ω) ∝ L_i (piecewise constant) as the records grow. A tree whose energies are all zero has
//! no density (`pdf` is 0, `sample` gives `None`): the strategy that uses it then takes no guided samples.

use super::parallax::Anchor;

/// An edge of the light: a quadrant holding more than this share of the refinement threshold is split too where
/// a sibling holds more than [`EDGE_CONTRAST`] times its energy.
const EDGE_SHARE: f64 = 1.0 / 16.0;
/// See [`EDGE_SHARE`].
const EDGE_CONTRAST: f64 = 4.0;
use super::shape::{Node, Shape, quadrant};
use crate::math::SampleRng;
use glam::{DVec2, Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// `1 / 4π`: the density of the uniform sphere.
const INV_FOUR_PI: f32 = 1.0 / (4.0 * PI);
/// Records are summed as fixed-point integers with this many fraction bits, so that any order of summation gives
/// the same energies bit for bit (the render is then the same with any number of threads).
const FRACTION_BITS: i32 = 48;
/// The largest value one record may add (2⁶⁰): larger ones are clamped, so that sums never overflow.
const MAX_RECORD: f64 = (1u64 << 60) as f64;

/// The square point of the unit direction `w`: `((cos θ + 1)/2, φ/2π)`, with θ measured from +z.
#[inline]
pub fn dir_to_square(w: Vec3) -> Vec2 {
    let cos_theta = w.z.clamp(-1.0, 1.0);
    let phi = w.y.atan2(w.x).rem_euclid(TAU);
    Vec2::new((cos_theta + 1.0) * 0.5, (phi / TAU).min(crate::math::ONE_MINUS_EPSILON))
}

/// The unit direction of the square point `s`: [`dir_to_square`]'s inverse.
#[inline]
pub fn square_to_dir(s: Vec2) -> Vec3 {
    square_to_dir_f64(s.as_dvec2())
}

/// [`square_to_dir`] from a point in f64, rounded once at the end (a deep leaf is only a few f32 steps wide).
#[inline]
fn square_to_dir_f64(s: DVec2) -> Vec3 {
    let cos_theta = 2.0 * s.x - 1.0;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin_phi, cos_phi) = (std::f64::consts::TAU * s.y).sin_cos();
    glam::DVec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta).as_vec3()
}

/// Sums of recorded values per leaf of a [`Shape`], in fixed point (order-independent).
#[derive(Clone, Debug)]
pub struct Sums {
    shape: Shape,
    /// Per node, per quadrant (only leaves receive records).
    sums: Vec<[u128; 4]>,
}

impl Sums {
    pub fn new(shape: Shape) -> Self {
        let sums = vec![[0; 4]; shape.nodes.len()];
        Self { shape, sums }
    }

    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// Adds `value` (≥ 0 and finite; anything else counts as a record of 0) at the direction's square point.
    #[inline]
    pub fn record(&mut self, s: Vec2, value: f32) {
        let (node, q) = self.shape.leaf(s);
        self.sums[node][q] = self.sums[node][q].saturating_add(fixed_point(value));
    }

    /// Adds `value` spread evenly over a square as wide as the leaf holding `s`, centred on `s` (Müller et al.
    /// 2019's directional box filter: a record informs the cells around its own, so that few records cover an
    /// opening's directions without holes). The square wraps around in φ and is cut at the poles (the energy
    /// stays whole). Leaves receive their share of the square's area.
    pub fn record_filtered(&mut self, s: Vec2, value: f32) {
        let side = self.shape.leaf_side(s) as f64;
        let (lo, hi) = (s.as_dvec2() - side * 0.5, s.as_dvec2() + side * 0.5);
        let (x0, x1) = (lo.x.max(0.0), hi.x.min(1.0));
        // φ wraps: the square's part below 0 or above 1 comes in from the other side.
        let mut pieces = [(lo.y.max(0.0), hi.y.min(1.0)), (0.0, 0.0)];
        if lo.y < 0.0 {
            pieces[1] = (lo.y + 1.0, 1.0);
        } else if hi.y > 1.0 {
            pieces[1] = (0.0, hi.y - 1.0);
        }
        let area = (x1 - x0) * side;
        if !(area > 0.0) || !(value > 0.0) {
            return;
        }
        for (y0, y1) in pieces.into_iter().filter(|(a, b)| b > a) {
            self.splat(0, DVec2::ZERO, 1.0, (DVec2::new(x0, y0), DVec2::new(x1, y1)), value as f64 / area);
        }
    }

    /// Adds `density` × (area of the box within each leaf) below `node` (square at `corner`, side `side`).
    fn splat(&mut self, node: usize, corner: DVec2, side: f64, (lo, hi): (DVec2, DVec2), density: f64) {
        let half = side * 0.5;
        for q in 0..4 {
            let c = corner + DVec2::new((q & 1) as f64, (q >> 1) as f64) * half;
            let (a, b) = (lo.max(c), hi.min(c + half));
            if b.x <= a.x || b.y <= a.y {
                continue;
            }
            match self.shape.nodes[node].children[q] {
                0 => {
                    let e = fixed_point((density * (b.x - a.x) * (b.y - a.y)) as f32);
                    self.sums[node][q] = self.sums[node][q].saturating_add(e);
                }
                child => self.splat(child as usize, c, half, (lo, hi), density),
            }
        }
    }

    /// The density the sums describe: each node's quadrant energies summed up from its leaves.
    pub fn density(&self) -> DTree {
        let mut energy = vec![[0.0f64; 4]; self.shape.nodes.len()];
        fn total(sums: &Sums, energy: &mut [[f64; 4]], node: usize) -> u128 {
            let mut sum = 0u128;
            for q in 0..4 {
                let e = match sums.shape.nodes[node].children[q] {
                    0 => sums.sums[node][q],
                    child => total(sums, energy, child as usize),
                };
                energy[node][q] = e as f64 * (-FRACTION_BITS as f64).exp2();
                sum = sum.saturating_add(e);
            }
            sum
        }
        total(self, &mut energy, 0);
        DTree { shape: self.shape.clone(), energy, anchor: None }
    }
}

/// `value` in fixed point, rounded; negative, NaN and infinite values count as 0, values above 2⁶⁰ as 2⁶⁰. Whole
/// and fraction are converted apart, each through u64 (one instruction; f64 → u128 is a library call), which
/// gives `round(v 2⁴⁸)` exactly: the fraction times 2⁴⁸ is exact in f64.
#[inline]
fn fixed_point(value: f32) -> u128 {
    let v = value as f64;
    if !(v > 0.0) || !v.is_finite() {
        return 0;
    }
    let v = v.min(MAX_RECORD);
    let whole = v.trunc();
    ((whole as u64 as u128) << FRACTION_BITS) + ((v - whole) * (FRACTION_BITS as f64).exp2()).round() as u64 as u128
}

/// A quadtree density over the sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct DTree {
    shape: Shape,
    /// Per node, per quadrant: the energy below it.
    energy: Vec<[f64; 4]>,
    /// Where its directions are seen from (`None`: from the shading point itself).
    anchor: Option<Anchor>,
}

impl Default for DTree {
    /// The root with no energy: no density.
    fn default() -> Self {
        Self { shape: Shape::default(), energy: vec![[0.0; 4]], anchor: None }
    }
}

impl DTree {
    /// A tree of the given shape with energy `energy(square cell)` in each leaf, for tests and synthetic guides:
    /// the leaf's square is given as (lower corner, side).
    pub fn from_leaf_energies(shape: Shape, energy: impl Fn(Vec2, f32) -> f32) -> Self {
        let mut sums = Sums::new(shape);
        fn fill(sums: &mut Sums, node: usize, corner: Vec2, side: f32, energy: &impl Fn(Vec2, f32) -> f32) {
            let half = side * 0.5;
            for q in 0..4 {
                let c = corner + Vec2::new((q & 1) as f32, (q >> 1) as f32) * half;
                match sums.shape.nodes[node].children[q] {
                    0 => sums.sums[node][q] = fixed_point(energy(c, half)),
                    child => fill(sums, child as usize, c, half, energy),
                }
            }
        }
        fill(&mut sums, 0, Vec2::ZERO, 1.0, &energy);
        sums.density()
    }

    /// All the energy recorded.
    pub fn total(&self) -> f64 {
        self.energy[0].iter().sum()
    }

    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// The same tree with its directions seen from `anchor`.
    pub fn with_anchor(self, anchor: Option<Anchor>) -> Self {
        Self { anchor, ..self }
    }

    /// Where its directions are seen from, if anywhere but the shading point.
    pub fn anchor(&self) -> Option<&Anchor> {
        self.anchor.as_ref()
    }

    /// The anchor, where it reaches `p`.
    #[inline]
    fn anchor_at(&self, p: Vec3) -> Option<Anchor> {
        self.anchor.filter(|a| a.reaches(p))
    }

    /// The density w.r.t. solid angle at the shading point `p` of drawing `wi` with [`DTree::sample_at`]: the
    /// quadtree's density of the anchor's direction times `dΩ_c/dΩ_p` (see [`Anchor`]), or [`DTree::pdf`] of
    /// `wi` itself where no anchor reaches `p`.
    #[inline]
    pub fn pdf_at(&self, p: Vec3, wi: Vec3) -> f32 {
        match self.anchor_at(p) {
            Some(a) => {
                let (d, jacobian) = a.from_point(p, wi);
                self.pdf(d) * jacobian
            }
            None => self.pdf(wi),
        }
    }

    /// Draws a direction at the shading point `p`: an anchor's direction from the quadtree, aimed at from `p`
    /// (see [`Anchor`]), or the quadtree's direction itself where no anchor reaches `p`; with its density (which
    /// [`DTree::pdf_at`] gives too, but for rounding).
    #[inline]
    pub fn sample_at(&self, p: Vec3, rng: &mut SampleRng) -> Option<(Vec3, f32)> {
        match self.anchor_at(p) {
            Some(a) => {
                let (d, pdf) = self.sample(rng)?;
                let (wi, jacobian) = a.to_point(p, d);
                Some((wi, pdf * jacobian))
            }
            None => self.sample(rng),
        }
    }

    /// Whether it has a density to draw from.
    #[inline]
    pub fn is_usable(&self) -> bool {
        self.total() > 0.0
    }

    /// Bytes it occupies (nodes and energies).
    pub fn bytes(&self) -> usize {
        self.shape.nodes.len() * (std::mem::size_of::<Node>() + std::mem::size_of::<[f64; 4]>())
            + std::mem::size_of::<Option<Anchor>>()
    }

    /// The density w.r.t. solid angle of drawing the unit direction `w`: `(1/4π) Π 4 E_q / Σ E`.
    #[inline]
    pub fn pdf(&self, w: Vec3) -> f32 {
        let (mut node, mut s) = (0usize, dir_to_square(w).as_dvec2());
        let mut p = 1.0f64;
        loop {
            let e = &self.energy[node];
            let total = e[0] + e[1] + e[2] + e[3];
            if !(total > 0.0) {
                return 0.0;
            }
            let (q, local) = quadrant(s);
            p *= 4.0 * e[q] / total;
            match self.shape.nodes[node].children[q] {
                0 => return (p * INV_FOUR_PI as f64) as f32,
                child => (node, s) = (child as usize, local),
            }
        }
    }

    /// Draws a direction: a quadrant per level in proportion to its energy (one uniform per level), then a
    /// uniform point of the leaf (two more); with the density of the leaf drawn from (which [`DTree::pdf`] gives
    /// too, but for a direction within rounding of a leaf's edge). `None` when the tree has no energy.
    #[inline]
    pub fn sample(&self, rng: &mut SampleRng) -> Option<(Vec3, f32)> {
        let (mut node, mut corner, mut side, mut p) = (0usize, DVec2::ZERO, 1.0f64, 1.0f64);
        loop {
            let e = &self.energy[node];
            let total = e[0] + e[1] + e[2] + e[3];
            if !(total > 0.0) {
                return None;
            }
            let mut u = rng.uniform() as f64 * total;
            // The last quadrant with energy takes what rounding leaves over.
            let last = (0..4).rev().find(|&q| e[q] > 0.0)?;
            let mut q = 0;
            while q < last && (u >= e[q] || e[q] == 0.0) {
                u -= e[q];
                q += 1;
            }
            side *= 0.5;
            corner += DVec2::new((q & 1) as f64, (q >> 1) as f64) * side;
            p *= 4.0 * e[q] / total;
            match self.shape.nodes[node].children[q] {
                0 => {
                    let u = rng.uniform_2d().as_dvec2();
                    let s = (corner + u * side).min(DVec2::splat(1.0 - f64::EPSILON));
                    return Some((square_to_dir_f64(s), (p * INV_FOUR_PI as f64) as f32));
                }
                child => node = child as usize,
            }
        }
    }

    /// The shape of the next recording (Müller's refinement): a quadrant holding more than `threshold` of the
    /// total energy is split into four, down to `max_depth` levels; so is one on an edge of the light, holding
    /// more than [`EDGE_SHARE`] of that and less than 1/[`EDGE_CONTRAST`] of a sibling's energy (a cell the edge
    /// crosses near its side holds little energy, and its lit sliver would otherwise get as little density as the
    /// whole cell: each such cell adds about its own solid angle over the light's to the relative variance). The
    /// rest stay leaves. With no energy, the root.
    pub fn refined_shape(&self, threshold: f64, max_depth: usize) -> Shape {
        let total = self.total();
        let mut shape = Shape::default();
        if !(total > 0.0) {
            return shape;
        }
        // (node of the new shape, node of self or None where self has a leaf, each quadrant's share of that leaf's
        // energy, depth): a quadrant of self that is a leaf spreads its energy evenly over the new quadrants.
        let mut stack = vec![(0usize, Some(0usize), 0.0f64, 1usize)];
        while let Some((new, old, spread, depth)) = stack.pop() {
            let brightest = old.map_or(spread, |o| self.energy[o].iter().copied().fold(0.0, f64::max));
            for q in 0..4 {
                let (energy, old_child) = match old {
                    Some(o) => (self.energy[o][q], self.shape.nodes[o].children[q]),
                    None => (spread, 0),
                };
                let edge = energy > EDGE_SHARE * threshold * total && brightest > EDGE_CONTRAST * energy;
                if depth < max_depth && (energy > threshold * total || edge) {
                    let child = shape.nodes.len();
                    shape.nodes.push(Node::default());
                    shape.nodes[new].children[q] = child as u32;
                    let next = if old_child != 0 { Some(old_child as usize) } else { None };
                    stack.push((child, next, energy / 4.0, depth + 1));
                }
            }
        }
        shape
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_and_direction_round_trip() {
        for i in 0..40 {
            for j in 0..40 {
                let s = Vec2::new((i as f32 + 0.5) / 40.0, (j as f32 + 0.5) / 40.0);
                let back = dir_to_square(square_to_dir(s));
                assert!((back - s).length() < 1e-5, "{s} -> {back}");
            }
        }
    }

    /// The recorded sums land in the leaf of their direction, in any order, bit for bit.
    #[test]
    fn sums_do_not_depend_on_the_order_of_records() {
        let shape = Shape::uniform(3);
        let records: Vec<(Vec2, f32)> = (0..5000)
            .map(|k| {
                let mut rng = SampleRng::new(1, k, 0);
                (rng.uniform_2d(), rng.uniform() * 10f32.powf(rng.uniform() * 12.0 - 6.0))
            })
            .collect();
        let (mut forward, mut backward) = (Sums::new(shape.clone()), Sums::new(shape));
        records.iter().for_each(|&(s, v)| forward.record(s, v));
        records.iter().rev().for_each(|&(s, v)| backward.record(s, v));
        assert_eq!(forward.density(), backward.density());
        let total: f64 = records.iter().map(|&(_, v)| v as f64).sum();
        assert!((forward.density().total() - total).abs() < 1e-9 * total);
    }

    /// The filtered record keeps its whole value, spreads it over the cells around its own, and wraps in φ.
    #[test]
    fn filtered_records_keep_their_energy() {
        let shape = Shape::uniform(4); // leaves of side 1/8
        let mut sums = Sums::new(shape.clone());
        sums.record_filtered(Vec2::new(0.5, 0.99), 8.0); // straddles φ = 1 and four leaves
        let d = sums.density();
        assert!((d.total() - 8.0).abs() < 1e-9, "{}", d.total());
        let filled = shape.leaves().iter().filter(|(c, side)| d.pdf(square_to_dir(*c + *side * 0.5)) > 0.0).count();
        assert_eq!(filled, 4, "two leaves across cos θ, two across the φ seam");
        // At a pole the square is cut and the energy stays whole.
        let mut sums = Sums::new(shape);
        sums.record_filtered(Vec2::new(0.01, 0.3), 2.0);
        assert!((sums.density().total() - 2.0).abs() < 1e-9);
    }

    /// ∫ pdf dω = 1 over the sphere, by the midpoint rule on a fine square grid, for trees of every kind.
    #[test]
    fn the_density_integrates_to_one() {
        let trees = [
            DTree::from_leaf_energies(Shape::uniform(1), |_, _| 1.0),
            DTree::from_leaf_energies(Shape::uniform(4), |c, _| 1.0 + c.x * 7.0 + (c.y * 9.0).sin().abs()),
            DTree::from_leaf_energies(Shape::towards(Vec2::new(0.3, 0.7), 6), |c, side| {
                if (c.x..c.x + side).contains(&0.3) && (c.y..c.y + side).contains(&0.7) { 5.0 } else { 0.1 }
            }),
        ];
        for tree in &trees {
            let n = 512;
            let mut integral = 0.0f64;
            for i in 0..n {
                for j in 0..n {
                    let s = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    integral += tree.pdf(square_to_dir(s)) as f64 * 4.0 * PI as f64 / (n * n) as f64;
                }
            }
            assert!((integral - 1.0).abs() < 1e-3, "∫ pdf = {integral}");
        }
    }

    /// Refinement splits the quadrants above the threshold, down to the deepest level allowed, and no others.
    #[test]
    fn refinement_follows_the_energy() {
        let hot = Vec2::new(0.61, 0.27);
        let tree = DTree::from_leaf_energies(Shape::towards(hot, 20), |c, side| {
            if (c.x..c.x + side).contains(&hot.x) && (c.y..c.y + side).contains(&hot.y) { 1.0 } else { 0.0 }
        });
        // All energy in one leaf 20 levels deep: its path is split at every level down to the limit, nothing else.
        let shape = tree.refined_shape(0.01, 20);
        assert_eq!(shape.nodes(), 20);
        assert_eq!(shape.depth(), 20);
        // All energy in one quadrant of a bare root: spread evenly over what the quadrant becomes, which splits
        // while a part holds more than 1%: 1 + 1 + 4 + 16 + 64 nodes.
        let coarse = DTree::from_leaf_energies(Shape::default(), |c, side| {
            if (c.x..c.x + side).contains(&hot.x) && (c.y..c.y + side).contains(&hot.y) { 1.0 } else { 0.0 }
        });
        assert_eq!(coarse.refined_shape(0.01, 20).nodes(), 86);
        let empty = DTree::default().refined_shape(0.01, 20);
        assert_eq!(empty.nodes(), 1);
        // Uniform energy: each level splits while a quadrant holds more than 1%: 4^-1, 4^-2, 4^-3 > 1% > 4^-4.
        let flat = DTree::from_leaf_energies(Shape::default(), |_, _| 1.0).refined_shape(0.01, 20);
        assert_eq!(flat.nodes(), 1 + 4 + 16 + 64);
    }

    /// A quadrant on an edge of the light (a sibling holds over four times its energy) is split though it holds
    /// less than the threshold, down to a sixteenth of it; a dim quadrant among equals is not.
    #[test]
    fn edges_of_the_light_are_refined() {
        // A bright quadrant (0.9), an edge (0.03, 3% of the total), two empty ones, at the threshold 5%: the bright
        // one splits by its energy, the edge by its contrast.
        let tree = DTree::from_leaf_energies(Shape::default(), |c, _| match (c.x > 0.4, c.y > 0.4) {
            (false, false) => 0.9,
            (true, false) => 0.03,
            _ => 0.0,
        });
        let total = tree.total();
        assert!(0.03 / total < 0.05 && 0.03 / total > EDGE_SHARE * 0.05);
        let shape = tree.refined_shape(0.05, 1 + 1);
        let split: Vec<bool> = (0..4).map(|q| shape.nodes[0].children[q] != 0).collect();
        assert_eq!(split, [true, true, false, false]);
        // Below the edge share, or without a brighter sibling, it stays a leaf.
        let dim = DTree::from_leaf_energies(Shape::default(), |c, _| if c.x > 0.4 && c.y < 0.4 { 0.001 } else { 0.9 });
        let shape = dim.refined_shape(0.05, 2);
        assert_eq!(shape.nodes[0].children[1], 0, "{:?}", shape.nodes[0]);
        let even = DTree::from_leaf_energies(Shape::default(), |_, _| 1.0);
        assert_eq!(even.refined_shape(0.3, 2).nodes(), 1, "no quadrant above 30%, none on an edge");
    }

    #[test]
    fn an_empty_tree_has_no_density() {
        let tree = DTree::default();
        assert_eq!(tree.pdf(Vec3::Z), 0.0);
        assert!(tree.sample(&mut SampleRng::new(0, 0, 0)).is_none());
        let mut sums = Sums::new(Shape::default());
        sums.sums[0][0] = u128::MAX - 1;
        sums.record(Vec2::splat(0.1), f32::MAX);
        assert_eq!(sums.sums[0][0], u128::MAX, "sums saturate");
        assert_eq!(fixed_point(f32::NAN), 0);
        assert_eq!(fixed_point(-1.0), 0);
        assert_eq!(fixed_point(f32::INFINITY), 0);
    }
}
