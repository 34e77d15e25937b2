//! Chi-square goodness-of-fit test of a sampler against its density, in the manner of Nori's warptest and
//! Mitsuba 3's `ChiSquareTest`: histogram N samples over a grid, integrate the density over every cell
//! numerically to get the expected counts, pool cells expecting fewer than 5, and compare.

use glam::{DVec2, DVec3, Vec2, Vec3};
use illumlab::math::SampleRng;
use illumlab::probe::chi2::{p_value, pearson};

/// Significance level of one test before the Šidák correction for the number of tests in a file: with a fresh
/// seed, a correct sampler fails a file of k tests with probability 1%.
pub const SIGNIFICANCE: f64 = 0.01;

pub struct Outcome {
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// ∫ pdf over the whole domain, numerically.
    pub integral: f64,
}

/// Directions binned by (cos θ, φ) about `axis`, with cos θ in [cos_min, 1] split into `res_cos` bins and φ into
/// `res_phi` bins; directions outside the cap fall into one extra bin, whose expected count is 1 − ∫_cap pdf.
/// `pdf` is w.r.t. solid angle. Integration: Gauss–Legendre with `sub` intervals per bin side.
pub struct SphereBins {
    pub axis: Vec3,
    pub cos_min: f64,
    pub res_cos: usize,
    pub res_phi: usize,
}

impl SphereBins {
    fn frame(&self) -> (DVec3, DVec3, DVec3) {
        let f = illumlab::math::Frame::from_z(self.axis);
        (f.s.as_dvec3(), f.t.as_dvec3(), f.n.as_dvec3())
    }

    fn cell(&self, w: Vec3) -> usize {
        let (s, t, n) = self.frame();
        let w = w.as_dvec3();
        let c = w.dot(n).clamp(-1.0, 1.0);
        if c < self.cos_min {
            return self.res_cos * self.res_phi;
        }
        let phi = w.dot(t).atan2(w.dot(s)).rem_euclid(std::f64::consts::TAU);
        let i = (((c - self.cos_min) / (1.0 - self.cos_min)) * self.res_cos as f64) as usize;
        let j = (phi / std::f64::consts::TAU * self.res_phi as f64) as usize;
        i.min(self.res_cos - 1) * self.res_phi + j.min(self.res_phi - 1)
    }

    fn expected(&self, pdf: &dyn Fn(Vec3) -> f64, sub: usize) -> Vec<f64> {
        let (s, t, n) = self.frame();
        let dc = (1.0 - self.cos_min) / self.res_cos as f64;
        let dphi = std::f64::consts::TAU / self.res_phi as f64;
        let mut out = Vec::with_capacity(self.res_cos * self.res_phi + 1);
        for i in 0..self.res_cos {
            for j in 0..self.res_phi {
                let c0 = self.cos_min + i as f64 * dc;
                let p0 = j as f64 * dphi;
                out.push(integrate_2d(
                    |c, phi| {
                        let sin = (1.0 - c * c).max(0.0).sqrt();
                        let w = s * (sin * phi.cos()) + t * (sin * phi.sin()) + n * c;
                        pdf(w.as_vec3())
                    },
                    DVec2::new(c0, p0),
                    DVec2::new(c0 + dc, p0 + dphi),
                    sub,
                ));
            }
        }
        let cap: f64 = out.iter().sum();
        out.push((1.0 - cap).max(0.0));
        out
    }

    /// Runs the test with `n` samples drawn by `sample` from uniforms of the given seed.
    pub fn test(
        &self,
        n: u64,
        seed: u64,
        sample: &dyn Fn(Vec2) -> Option<Vec3>,
        pdf: &dyn Fn(Vec3) -> f64,
        sub: usize,
    ) -> Outcome {
        let mut observed = vec![0.0; self.res_cos * self.res_phi + 1];
        let mut drawn = 0u64;
        for k in 0..n {
            let mut rng = SampleRng::new(seed, k, 0);
            if let Some(w) = sample(rng.uniform_2d()) {
                assert!(w.is_finite() && (w.length() - 1.0).abs() < 1e-4, "sample {w:?} is not a unit vector");
                observed[self.cell(w)] += 1.0;
                drawn += 1;
            }
        }
        assert_eq!(drawn, n, "the sampler failed to draw some samples");
        let expected = self.expected(pdf, sub);
        let integral = expected[..expected.len() - 1].iter().sum::<f64>();
        if std::env::var_os("CHI2_DEBUG").is_some() {
            let mut cells: Vec<(f64, usize)> = observed
                .iter()
                .zip(&expected)
                .enumerate()
                .map(|(i, (&o, &e))| ((o - e * n as f64).powi(2) / (e * n as f64).max(1e-9), i))
                .collect();
            cells.sort_by(|a, b| b.0.total_cmp(&a.0));
            for &(r, i) in cells.iter().take(8) {
                eprintln!("cell {i}: observed {} expected {:.1} (χ² {r:.1})", observed[i], expected[i] * n as f64);
            }
        }
        let (statistic, dof) = pearson(&observed, &expected, n as f64);
        Outcome { statistic, dof, p_value: p_value(statistic, dof), integral }
    }
}

/// Points on a triangle, binned on a `res × res` grid over (s, t) ∈ [0,1]², s = b₁ + b₂ (how far from the first
/// vertex) and t = b₂/(b₁ + b₂) (across), which covers the triangle with no cut cells. `pdf_area` is w.r.t.
/// area; dA = 2A s ds dt, so the density in (s, t) is `pdf_area · 2A · s`.
pub fn triangle_test(
    tri: [Vec3; 3],
    res: usize,
    n: u64,
    seed: u64,
    sample: &dyn Fn(Vec2) -> Vec3,
    pdf_area: &dyn Fn(Vec3) -> f64,
) -> Outcome {
    let edges: Vec<f64> = (0..=res).map(|i| i as f64 / res as f64).collect();
    triangle_grid_test(tri, &edges, &edges, 2, n, seed, sample, pdf_area)
}

/// As [`triangle_test`], with the cells' edges in s and in t given (increasing, from 0 to 1): a grid refined
/// where the density peaks (a narrow lobe) integrates it accurately. `sub` Gauss intervals per cell side.
#[allow(clippy::too_many_arguments)]
pub fn triangle_grid_test(
    tri: [Vec3; 3],
    s_edges: &[f64],
    t_edges: &[f64],
    sub: usize,
    n: u64,
    seed: u64,
    sample: &dyn Fn(Vec2) -> Vec3,
    pdf_area: &dyn Fn(Vec3) -> f64,
) -> Outcome {
    let [a, b, c] = tri.map(|v| v.as_dvec3());
    let (e1, e2) = (b - a, c - a);
    let area2 = e1.cross(e2).length();
    let st = triangle_coordinates(tri);
    let (rs, rt) = (s_edges.len() - 1, t_edges.len() - 1);
    let find = |edges: &[f64], x: f64| edges.partition_point(|&e| e <= x).clamp(1, edges.len() - 1) - 1;
    let mut observed = vec![0.0; rs * rt];
    for k in 0..n {
        let mut rng = SampleRng::new(seed, k, 0);
        let x = sample(rng.uniform_2d());
        let (s, t) = st(x);
        observed[find(s_edges, s) * rt + find(t_edges, t)] += 1.0;
    }
    let mut expected = Vec::with_capacity(rs * rt);
    for i in 0..rs {
        for j in 0..rt {
            expected.push(integrate_2d(
                |s, t| pdf_area((a + e1 * (s * (1.0 - t)) + e2 * (s * t)).as_vec3()) * area2 * s,
                DVec2::new(s_edges[i], t_edges[j]),
                DVec2::new(s_edges[i + 1], t_edges[j + 1]),
                sub,
            ));
        }
    }
    let integral = expected.iter().sum();
    let (statistic, dof) = pearson(&observed, &expected, n as f64);
    Outcome { statistic, dof, p_value: p_value(statistic, dof), integral }
}

/// The (s, t) coordinates of [`triangle_test`] of a point in the triangle's plane; panics for a point outside.
pub fn triangle_coordinates(tri: [Vec3; 3]) -> impl Fn(Vec3) -> (f64, f64) {
    let [a, b, c] = tri.map(|v| v.as_dvec3());
    let (e1, e2) = (b - a, c - a);
    // Barycentrics of a point in the triangle's plane by least squares on the two edges.
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = d11 * d22 - d12 * d12;
    move |p: Vec3| {
        let r = p.as_dvec3() - a;
        let (r1, r2) = (r.dot(e1), r.dot(e2));
        let bc = DVec2::new((d22 * r1 - d12 * r2) / det, (d11 * r2 - d12 * r1) / det);
        assert!(bc.x >= -1e-4 && bc.y >= -1e-4 && bc.x + bc.y <= 1.0 + 1e-4, "point outside the triangle: {bc:?}");
        let s = bc.x + bc.y;
        (s.clamp(0.0, 1.0), if s > 0.0 { (bc.y / s).clamp(0.0, 1.0) } else { 0.0 })
    }
}

/// A discrete sampler of indices against its probabilities: `sample(u)` returns an index and the probability it
/// claims for it, which must be `probabilities[i]` (to f32 rounding).
pub fn discrete_test(probabilities: &[f64], samples: u64, seed: u64, sample: &dyn Fn(f32) -> (usize, f32)) -> Outcome {
    let mut observed = vec![0.0; probabilities.len()];
    for k in 0..samples {
        let mut rng = SampleRng::new(seed, k, 0);
        let (i, p) = sample(rng.uniform());
        assert!((p as f64 - probabilities[i]).abs() <= 1e-6 * probabilities[i], "index {i} claims p = {p}");
        observed[i] += 1.0;
    }
    let (statistic, dof) = pearson(&observed, probabilities, samples as f64);
    Outcome { statistic, dof, p_value: p_value(statistic, dof), integral: probabilities.iter().sum() }
}

/// Composite 3-point Gauss–Legendre rule over the rectangle [lo, hi] with `sub` intervals per side. Its nodes
/// are interior, so a density that jumps on a cell's edge (the hemisphere's rim) is integrated correctly.
fn integrate_2d(f: impl Fn(f64, f64) -> f64, lo: DVec2, hi: DVec2, sub: usize) -> f64 {
    const X: [f64; 3] = [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4];
    const W: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let h = (hi - lo) / sub as f64;
    let mut sum = 0.0;
    for i in 0..sub {
        for j in 0..sub {
            let c = lo + DVec2::new(i as f64 + 0.5, j as f64 + 0.5) * h;
            for (xa, wa) in X.iter().zip(W) {
                for (xb, wb) in X.iter().zip(W) {
                    sum += wa * wb * f(c.x + 0.5 * h.x * xa, c.y + 0.5 * h.y * xb);
                }
            }
        }
    }
    sum * h.x * h.y / 4.0
}

/// Šidák-corrected per-test level for `k` tests sharing a family-wise level of [`SIGNIFICANCE`].
pub fn per_test_level(k: usize) -> f64 {
    1.0 - (1.0 - SIGNIFICANCE).powf(1.0 / k as f64)
}
