//! Chi-square goodness of fit of a strategy's sampling at the probed point against its own `pdf(ω)`, as Nori's
//! warptest does it: the samples' histogram over cells beside the pdf integrated over each cell, Pearson's
//! statistic after pooling the cells that expect fewer than 5 samples, and its p-value. Hemisphere strategies
//! and MIS are binned over the whole sphere in equal-solid-angle cells of (cos θ, φ) about the normal; light
//! strategies on their own domain, cells of each light triangle (a direction is binned where it meets the
//! triangle it was aimed at), where their density is smooth however small the light looks. A sample that could
//! not be drawn falls in one more cell, which expects `N (1 − ∫p)`. MIS draws from its two techniques, n_i
//! directions of technique i per pixel sample: each technique is tested on its own domain with its share of the
//! draws, and the smaller p-value, Šidák-corrected for two, is MIS's.

use super::adaptive::{Refinement, integrate_triangle};
use super::density::density;
use crate::math::{Frame, SampleRng};
use crate::render::strategy::guided;
use crate::render::strategy::light::faces;
use crate::render::{Domain, Reached, SampleContext, ShadingPoint, Strategy, Target};
use glam::{DVec2, DVec3, Vec3};
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF};

/// The result of one test.
#[derive(Clone, Debug, Serialize)]
pub struct ChiSquare {
    pub samples: u64,
    pub statistic: f64,
    pub dof: usize,
    pub p_value: f64,
    /// ∫ p dω over the cells: the strategy's coverage (1 unless some draws fail by design).
    pub integral: f64,
    /// "sphere" or "light triangles".
    pub binning: &'static str,
    /// Per cell: samples observed and expected (before pooling), the failure cell last.
    #[serde(skip)]
    pub cells: Vec<(f64, f64)>,
    /// The technique whose draws were binned.
    #[serde(skip)]
    pub strategy: Option<Strategy>,
    /// MIS: the test of each technique.
    pub parts: Vec<ChiSquare>,
}

/// The p-value below which a single test fails, at a family-wise level of 1% over `tests` tests (Šidák).
pub fn level(tests: usize) -> f64 {
    1.0 - 0.99f64.powf(1.0 / tests.max(1) as f64)
}

const Z_CELLS: usize = 24;
const PHI_CELLS: usize = 48;
/// Each light triangle is cut into 4^k cells.
const TRIANGLE_DEPTH: u32 = 2;

/// Tests `samples` draws of `strategy` at `sp` (streams of `seed`) against its density. A mixture (MIS, or
/// `guided`'s guide, light and BRDF parts) is tested part by part, each binned as its own kind is.
pub fn chi_square(ctx: &SampleContext, sp: &ShadingPoint, strategy: Strategy, samples: u64, seed: u64) -> ChiSquare {
    let share = |w: f64| (samples as f64 * w).round().max(1.0) as u64;
    let parts: Vec<(ChiSquare, f64)> = match strategy.domain() {
        Domain::Mixture => {
            let [n0, n1] = ctx.mis.samples.map(|n| n as f64);
            (ctx.mis.techniques.iter().zip([n0, n1]))
                .filter(|(_, n)| *n > 0.0)
                .enumerate()
                .map(|(i, (&t, n))| {
                    let w = n / (n0 + n1);
                    (chi_square(ctx, sp, t, share(w), seed + i as u64), w)
                })
                .collect()
        }
        Domain::Learned => {
            let [c_g, c_l, c_b] = guided::weights(ctx, sp).map(|c| c as f64);
            let mut parts = Vec::new();
            if c_g > 0.0 {
                parts.push((chi_square_guide(ctx, sp, share(c_g), seed), c_g));
            }
            if c_l > 0.0 {
                parts.push((chi_square(ctx, sp, Strategy::Emitter, share(c_l), seed + 1), c_l));
            }
            if c_b > 0.0 {
                parts.push((chi_square(ctx, sp, Strategy::Brdf, share(c_b), seed + 2), c_b));
            }
            parts
        }
        _ => Vec::new(),
    };
    if !parts.is_empty() {
        let k = parts.len() as i32;
        let min_p = parts.iter().map(|(c, _)| c.p_value).fold(1.0, f64::min);
        return ChiSquare {
            samples: parts.iter().map(|(c, _)| c.samples).sum(),
            statistic: parts.iter().map(|(c, _)| c.statistic).sum(),
            dof: parts.iter().map(|(c, _)| c.dof).sum(),
            p_value: 1.0 - (1.0 - min_p).powi(k),
            integral: parts.iter().map(|(c, w)| c.integral * w).sum::<f64>(),
            binning: "per technique",
            cells: Vec::new(),
            strategy: Some(strategy),
            parts: parts.into_iter().map(|(c, _)| c).collect(),
        };
    }
    chi_square_against(ctx, sp, strategy, samples, seed, &|w, via| match via {
        Some(_) if strategy.domain() == Domain::Lights => strategy.pdf(ctx, sp, w, via),
        _ => density(ctx, sp, strategy, w),
    })
}

/// `guided`'s guide part alone: its quadtree's draws at the point against the quadtree's density, on the sphere.
fn chi_square_guide(ctx: &SampleContext, sp: &ShadingPoint, samples: u64, seed: u64) -> ChiSquare {
    let dtree = ctx.guide.map(|g| g.dtree(sp.p));
    let pdf = |w: Vec3, _: Option<Reached>| dtree.map_or(0.0, |d| d.pdf_at(sp.p, w));
    let frame = Frame::from_z(sp.n);
    let observed_cell = |k: u64| {
        let mut rng = SampleRng::new(seed, u64::MAX - 13, k);
        dtree.and_then(|d| d.sample_at(sp.p, &mut rng)).map(|(w, _)| sphere_cell(frame.to_local(w)))
    };
    tally(sphere_cells(sp, &pdf), samples, "sphere (guide)", None, observed_cell)
}

/// [`chi_square`] against another density (to show that a wrong one fails): `pdf(ω, via)`.
pub fn chi_square_against(
    ctx: &SampleContext,
    sp: &ShadingPoint,
    strategy: Strategy,
    samples: u64,
    seed: u64,
    pdf: &(dyn Fn(Vec3, Option<Reached>) -> f32 + Sync),
) -> ChiSquare {
    let (binning, cells) = match strategy.domain() {
        Domain::Lights => ("light triangles", light_cells(ctx, sp, pdf)),
        _ => ("sphere", sphere_cells(sp, pdf)),
    };
    let frame = Frame::from_z(sp.n);
    let lights: Vec<u32> = ctx.scene.emitters.clone();
    let observed_cell = |k: u64| {
        let mut rng = SampleRng::new(seed, u64::MAX - 11, k);
        strategy.sample(ctx, sp, &mut rng).and_then(|s| match (strategy.domain(), s.target) {
            (Domain::Lights, Target::Emitter { triangle, point }) => {
                let slot = lights.iter().position(|&t| t == triangle)?;
                let tri = &ctx.scene.triangles[triangle as usize];
                Some(slot * cells_per_triangle() + triangle_cell(tri.v, point))
            }
            (Domain::Lights, Target::Trace) => None,
            _ => Some(sphere_cell(frame.to_local(s.wi))),
        })
    };
    tally(cells, samples, binning, Some(strategy), observed_cell)
}

/// Pearson's test of `samples` draws, draw k falling in cell `observed_cell(k)` (`None`: no direction, or one
/// outside every cell), against the cells' expected probabilities; the rest of the probability is the failure
/// cell's.
fn tally(
    mut cells: Vec<f64>,
    samples: u64,
    binning: &'static str,
    strategy: Option<Strategy>,
    observed_cell: impl Fn(u64) -> Option<usize>,
) -> ChiSquare {
    let failed = cells.len();
    let mut observed = vec![0.0; cells.len() + 1];
    for k in 0..samples {
        observed[observed_cell(k).unwrap_or(failed)] += 1.0;
    }
    let integral: f64 = cells.iter().sum();
    cells.push((1.0 - integral).max(0.0));
    let (statistic, dof) = pearson(&observed, &cells, samples as f64);
    let p_value = p_value(statistic, dof);
    let cells = observed.into_iter().zip(cells.iter().map(|e| e * samples as f64)).collect();
    ChiSquare { samples, statistic, dof, p_value, integral, binning, cells, strategy, parts: Vec::new() }
}

/// The cell a direction falls in, for a test binned on the sphere or (`lights`) on the light triangles: the cell
/// of the first facing emitter triangle it passes through (`None` if it meets none).
fn cell_of(ctx: &SampleContext, sp: &ShadingPoint, lights: bool, wi: Vec3) -> Option<usize> {
    if !lights {
        return Some(sphere_cell(Frame::from_z(sp.n).to_local(wi)));
    }
    let scene = ctx.scene;
    let nearest = scene
        .emitters
        .iter()
        .enumerate()
        .filter(|(_, t)| faces(&scene.triangles[**t as usize], sp.p))
        .filter_map(|(slot, &t)| {
            let tri = &scene.triangles[t as usize];
            super::density::intersect(sp.p, wi, tri.v).map(|x| (slot, tri.v, x, (x - sp.p).length_squared()))
        })
        .min_by(|a, b| a.3.total_cmp(&b.3))?;
    Some(nearest.0 * cells_per_triangle() + triangle_cell(nearest.1, nearest.2))
}

impl ChiSquare {
    /// The test as Nori's warptest shows it, on the hemisphere disks of the probe's picture: the draws observed
    /// per cell, the counts the pdf expects (same log scale), and the residual (o − e)/√e (±4, diverging). MIS:
    /// one row per technique.
    pub fn picture(&self, ctx: &SampleContext, sp: &ShadingPoint, size: usize) -> super::Picture {
        use super::picture::{Picture, density_colour, disk_point, residual_colour};
        if !self.parts.is_empty() {
            let rows: Vec<Picture> = self.parts.iter().map(|p| p.picture(ctx, sp, size)).collect();
            return Picture::stack(&rows, 8);
        }
        // Binned on light triangles, or (guided's guide part too) on the sphere.
        let lights = self.strategy.is_some_and(|s| s.domain() == Domain::Lights);
        let frame = Frame::from_z(sp.n);
        let top = self.cells.iter().map(|c| c.0.max(c.1)).fold(1.0, f64::max).log10() as f32;
        // Per pixel on the disk, the cell its direction falls in (if any).
        let cells: Vec<Option<Option<usize>>> = (0..size * size)
            .map(|i| {
                let d = disk_point(i, size)?;
                Some(cell_of(ctx, sp, lights, frame.to_world(crate::math::disk_to_hemisphere(d))))
            })
            .collect();
        let gap = 8;
        let mut pic = Picture::blank(3 * size + 2 * gap, size);
        for (panel, x0) in [0, size + gap, 2 * (size + gap)].into_iter().enumerate() {
            for (i, cell) in cells.iter().enumerate() {
                let Some(cell) = cell else { continue };
                let (o, e) = cell.and_then(|c| self.cells.get(c)).copied().unwrap_or((0.0, 0.0));
                let colour = match panel {
                    0 => density_colour(o as f32, top),
                    1 => density_colour(e as f32, top),
                    _ => residual_colour(if e > 0.0 {
                        ((o - e) / e.sqrt()) as f32
                    } else if o > 0.0 {
                        4.0
                    } else {
                        0.0
                    }),
                };
                pic.put(x0 + i % size, i / size, colour);
            }
        }
        pic
    }
}

fn cells_per_triangle() -> usize {
    4usize.pow(TRIANGLE_DEPTH)
}

/// The cell of a local direction: cos θ in Z_CELLS equal bands over [−1, 1], φ in PHI_CELLS (equal solid angle).
fn sphere_cell(w: Vec3) -> usize {
    let z = (((w.z + 1.0) * 0.5 * Z_CELLS as f32) as usize).min(Z_CELLS - 1);
    let phi = w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU);
    let p = ((phi / std::f32::consts::TAU * PHI_CELLS as f32) as usize).min(PHI_CELLS - 1);
    z * PHI_CELLS + p
}

/// The probability of each sphere cell, `∫ p dω` with dω = d(cos θ) dφ, adaptively.
fn sphere_cells(sp: &ShadingPoint, pdf: &(dyn Fn(Vec3, Option<Reached>) -> f32 + Sync)) -> Vec<f64> {
    use rayon::prelude::*;
    let frame = Frame::from_z(sp.n);
    let f = |z: f64, phi: f64| {
        let r = (1.0 - z * z).max(0.0).sqrt();
        let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
        pdf(frame.to_world(w), None) as f64
    };
    let (dz, dphi) = (2.0 / Z_CELLS as f64, std::f64::consts::TAU / PHI_CELLS as f64);
    (0..Z_CELLS * PHI_CELLS)
        .into_par_iter()
        .map(|i| {
            let lo = DVec2::new(-1.0 + (i / PHI_CELLS) as f64 * dz, (i % PHI_CELLS) as f64 * dphi);
            let whole = gauss(&f, lo, lo + DVec2::new(dz, dphi));
            adaptive_rect(&f, lo, lo + DVec2::new(dz, dphi), whole, 1e-7, 0)
        })
        .collect()
}

/// 3×3 Gauss–Legendre on a rectangle (interior nodes: a density that jumps on an edge, the horizon, is fine).
fn gauss(f: &impl Fn(f64, f64) -> f64, lo: DVec2, hi: DVec2) -> f64 {
    const X: [f64; 3] = [-0.774_596_669_241_483_4, 0.0, 0.774_596_669_241_483_4];
    const W: [f64; 3] = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
    let (c, h) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
    let mut sum = 0.0;
    for (xa, wa) in X.iter().zip(W) {
        for (xb, wb) in X.iter().zip(W) {
            sum += wa * wb * f(c.x + h.x * xa, c.y + h.y * xb);
        }
    }
    sum * h.x * h.y
}

fn adaptive_rect(f: &impl Fn(f64, f64) -> f64, lo: DVec2, hi: DVec2, whole: f64, tol: f64, depth: u32) -> f64 {
    let m = (lo + hi) * 0.5;
    let quads = [
        (lo, m),
        (DVec2::new(m.x, lo.y), DVec2::new(hi.x, m.y)),
        (DVec2::new(lo.x, m.y), DVec2::new(m.x, hi.y)),
        (m, hi),
    ];
    let parts = quads.map(|(a, b)| gauss(f, a, b));
    let sum: f64 = parts.iter().sum();
    if (sum - whole).abs() <= tol || depth >= 7 {
        return sum;
    }
    quads.iter().zip(parts).map(|(&(a, b), part)| adaptive_rect(f, a, b, part, tol * 0.25, depth + 1)).sum()
}

/// The cell of point x of triangle (a, b, c): the leaf of TRIANGLE_DEPTH midpoint subdivisions that holds it.
fn triangle_cell([a, b, c]: [Vec3; 3], x: Vec3) -> usize {
    // Barycentric coordinates, then descend: the corner children 0..2 or the middle 3.
    let (e1, e2, d) = ((b - a).as_dvec3(), (c - a).as_dvec3(), (x - a).as_dvec3());
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d1, d2) = (d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let v = ((d22 * d1 - d12 * d2) / det).clamp(0.0, 1.0);
    let w = ((d11 * d2 - d12 * d1) / det).clamp(0.0, 1.0);
    let mut bary = [1.0 - v - w, v, w];
    let mut cell = 0;
    for _ in 0..TRIANGLE_DEPTH {
        // Children of (A, B, C): [A, AB, CA], [AB, B, BC], [CA, BC, C], [AB, BC, CA] (as in `adaptive`).
        let (child, next) = if bary[0] >= 0.5 {
            (0, [2.0 * bary[0] - 1.0, 2.0 * bary[1], 2.0 * bary[2]])
        } else if bary[1] >= 0.5 {
            (1, [2.0 * bary[0], 2.0 * bary[1] - 1.0, 2.0 * bary[2]])
        } else if bary[2] >= 0.5 {
            (2, [2.0 * bary[0], 2.0 * bary[1], 2.0 * bary[2] - 1.0])
        } else {
            // The middle child (AB, BC, CA): weights of its corners.
            (3, [1.0 - 2.0 * bary[2], 1.0 - 2.0 * bary[0], 1.0 - 2.0 * bary[1]])
        };
        cell = cell * 4 + child;
        bary = next;
    }
    cell
}

/// The sub-triangles of (a, b, c) in [`triangle_cell`]'s order.
fn triangle_leaves(tri: [DVec3; 3], depth: u32) -> Vec<[DVec3; 3]> {
    if depth == 0 {
        return vec![tri];
    }
    let [a, b, c] = tri;
    let (ab, bc, ca) = ((a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5);
    [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
        .into_iter()
        .flat_map(|t| triangle_leaves(t, depth - 1))
        .collect()
}

/// The probability of each light-triangle cell: `∫ p(ω(x)) (n_Δ·−ω) / ‖x − p‖² dA`, for every emitter triangle
/// in the scene's order (zero for those p does not face).
fn light_cells(
    ctx: &SampleContext,
    sp: &ShadingPoint,
    pdf: &(dyn Fn(Vec3, Option<Reached>) -> f32 + Sync),
) -> Vec<f64> {
    use rayon::prelude::*;
    let p = sp.p.as_dvec3();
    ctx.scene
        .emitters
        .par_iter()
        .flat_map_iter(|&t| {
            let tri = &ctx.scene.triangles[t as usize];
            let facing = faces(tri, sp.p);
            let n_light = tri.n.as_dvec3();
            triangle_leaves(tri.v.map(|v| v.as_dvec3()), TRIANGLE_DEPTH).into_iter().map(move |leaf| {
                if !facing {
                    return 0.0;
                }
                let mut f = |x: DVec3| {
                    let d = x - p;
                    let r2 = d.length_squared();
                    let w = d / r2.sqrt();
                    let cos_light = -n_light.dot(w);
                    if !(cos_light > 0.0) {
                        return DVec3::ZERO;
                    }
                    let via = Reached { triangle: t, point: x.as_vec3() };
                    DVec3::splat(pdf(w.as_vec3(), Some(via)) as f64 * cos_light / r2)
                };
                let r = Refinement { tolerance: 1e-8, max_depth: 10, max_nodes: 200_000 };
                integrate_triangle(leaf, &mut f, r, &mut 0).x
            })
        })
        .collect()
}

/// The probability that a statistic this large or larger arises by chance: the chi-square distribution's upper
/// tail with `dof` degrees of freedom (0 for an infinite statistic).
pub fn p_value(statistic: f64, dof: usize) -> f64 {
    if !statistic.is_finite() {
        return 0.0;
    }
    ChiSquared::new(dof.max(1) as f64).map(|d| d.sf(statistic)).unwrap_or(0.0)
}

/// Pearson's statistic of `observed` counts against `expected_fraction` of `n` draws per cell, after pooling every
/// cell expecting fewer than 5 samples into one, and its degrees of freedom.
pub fn pearson(observed: &[f64], expected_fraction: &[f64], n: f64) -> (f64, usize) {
    let (mut stat, mut cells) = (0.0, 0usize);
    let (mut pooled_obs, mut pooled_exp) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected_fraction) {
        let e = e * n;
        if e < 5.0 {
            pooled_obs += o;
            pooled_exp += e;
        } else {
            stat += (o - e) * (o - e) / e;
            cells += 1;
        }
    }
    if pooled_exp > 0.0 {
        stat += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
        cells += 1;
    } else if pooled_obs > 0.0 {
        stat = f64::INFINITY; // samples where the density says none can be
    }
    (stat, cells.saturating_sub(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_cells_match_the_leaves() {
        let tri = [Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.3, 1.5, 0.0)];
        let leaves = triangle_leaves(tri.map(|v| v.as_dvec3()), TRIANGLE_DEPTH);
        for (i, leaf) in leaves.iter().enumerate() {
            let centroid = ((leaf[0] + leaf[1] + leaf[2]) / 3.0).as_vec3();
            assert_eq!(triangle_cell(tri, centroid), i);
        }
        let _ = DVec3::ZERO;
    }
}
