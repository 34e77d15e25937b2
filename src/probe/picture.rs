//! The hemisphere picture: three disks side by side in Lambert's equal-area projection (areas are solid
//! angles, `math::equal_area`), seen from above the surface (the centre is n, the rim the horizon, +x of the
//! local frame to the right):
//!
//! 1. the integrand `f_r L_i (ω·n)` normalised by the point's integral, a density: where an ideal strategy would
//!    sample (occluders show as holes);
//! 2. the strategy's density `p(ω)` on the same log colour scale;
//! 3. their ratio `(f_r L_i (ω·n) / L_o) / p(ω)`: white where the strategy is ideal, red where it samples too
//!    rarely (high-weight samples: fireflies), blue where too often.
//!
//! Over them, each switchable: the light triangles' outlines as they project (spherical triangles), ω_r, and the
//! last samples as dots coloured by their weight `f L cos / p` relative to L_o on a log scale (zero-valued ones
//! grey; MIS's second technique as rings).

use super::density::density;
use crate::math::{Frame, SOLID_ANGLE_PER_DISK_AREA, disk_to_hemisphere, hemisphere_to_disk, luminance, reflect};
use crate::render::strategy::light::faces;
use crate::render::{Outcome, SampleContext, SampleRecord, ShadingPoint, Strategy, reached};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Which parts of the picture to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layers {
    pub integrand: bool,
    pub density: bool,
    pub ratio: bool,
    pub outlines: bool,
    pub samples: bool,
    /// The learned guide's density at the point (where a guide is given).
    pub guide: bool,
}

impl Default for Layers {
    fn default() -> Self {
        Self { integrand: true, density: true, ratio: true, outlines: true, samples: true, guide: true }
    }
}

/// The name of the projection, for captions.
pub const PROJECTION: &str =
    "Lambert azimuthal equal-area projection: disk areas are solid angles (dω = 2 dA); centre = n, rim = horizon";

/// Decades of the log colour scale of the density disks.
pub const DECADES: f32 = 6.0;

/// The integrand and the density on a grid of disk pixels (row-major, `size`², NaN outside the disk).
#[derive(Clone, Debug)]
pub struct Maps {
    pub size: usize,
    /// `luminance(f_r L_i (ω·n)) / L_o` (a density: ∫ = 1 over the hemisphere).
    pub integrand: Vec<f32>,
    pub density: Vec<f32>,
    /// The learned guide's density p_guide(ω) at the point's spatial leaf, where the context has a guide.
    pub guide: Option<Vec<f32>>,
    /// The strategy's probability of sampling below the horizon (where the disk shows nothing).
    pub below_horizon: f32,
}

impl Maps {
    /// Evaluates both at each disk pixel's centre: one traced ray per pixel for L_i, the density of `strategy`.
    /// `truth` is the point's L_o luminance (the integrand's normaliser).
    pub fn new(ctx: &SampleContext, sp: &ShadingPoint, strategy: Strategy, truth: f32, size: usize) -> Self {
        let frame = Frame::from_z(sp.n);
        let values: Vec<(f32, f32)> = (0..size * size)
            .into_par_iter()
            .map(|i| {
                let Some(d) = disk_point(i, size) else { return (f32::NAN, f32::NAN) };
                let wi = frame.to_world(disk_to_hemisphere(d));
                let f = sp.material.eval_brdf(sp.n, sp.wo, wi);
                let li = match reached(ctx.scene, sp, wi) {
                    Some(r) if f != Vec3::ZERO => ctx.scene.emitted(r.triangle, -wi),
                    _ => Vec3::ZERO,
                };
                let g = luminance(f * li) * sp.n.dot(wi).max(0.0);
                (if truth > 0.0 { g / truth } else { 0.0 }, density(ctx, sp, strategy, wi))
            })
            .collect();
        // ∫ p over the upper hemisphere from the grid (dω = 2 dA, a pixel's area (2/size)²); the rest is below.
        let cell = SOLID_ANGLE_PER_DISK_AREA * (2.0 / size as f32).powi(2);
        let above: f32 = values.iter().filter(|v| v.1.is_finite()).map(|v| v.1 * cell).sum();
        let guide = ctx.guide.map(|g| {
            let dtree = g.dtree(sp.p);
            (0..size * size)
                .map(|i| {
                    disk_point(i, size).map_or(f32::NAN, |d| dtree.pdf_at(sp.p, frame.to_world(disk_to_hemisphere(d))))
                })
                .collect()
        });
        Self {
            size,
            integrand: values.iter().map(|v| v.0).collect(),
            density: values.iter().map(|v| v.1).collect(),
            guide,
            below_horizon: (1.0 - above).clamp(0.0, 1.0),
        }
    }
}

/// The disk point at the centre of pixel i of a `size`² grid (row-major, rows from the top), if it is on the disk.
pub(super) fn disk_point(i: usize, size: usize) -> Option<Vec2> {
    let d = Vec2::new(
        ((i % size) as f32 + 0.5) / size as f32 * 2.0 - 1.0,
        1.0 - ((i / size) as f32 + 0.5) / size as f32 * 2.0,
    );
    (d.length_squared() <= 1.0).then_some(d)
}

/// An RGBA image.
pub struct Picture {
    pub width: usize,
    pub height: usize,
    pub rgba: Vec<u8>,
}

impl Picture {
    /// An image of the background colour.
    pub fn blank(width: usize, height: usize) -> Self {
        Self::new(width, height)
    }

    /// Pictures one above the other, `gap` pixels apart.
    pub fn stack(rows: &[Picture], gap: usize) -> Self {
        let width = rows.iter().map(|r| r.width).max().unwrap_or(1);
        let height = rows.iter().map(|r| r.height).sum::<usize>() + gap * rows.len().saturating_sub(1);
        let mut out = Self::new(width, height.max(1));
        let mut y0 = 0;
        for r in rows {
            for y in 0..r.height {
                let (from, to) = (y * r.width * 4, ((y0 + y) * width) * 4);
                out.rgba[to..to + r.width * 4].copy_from_slice(&r.rgba[from..from + r.width * 4]);
            }
            y0 += r.height + gap;
        }
        out
    }

    pub(super) fn put(&mut self, x: usize, y: usize, c: [u8; 4]) {
        self.blend(x as i32, y as i32, c);
    }

    fn new(width: usize, height: usize) -> Self {
        let mut rgba = vec![0; width * height * 4];
        rgba.chunks_mut(4).for_each(|p| p.copy_from_slice(&BACKGROUND));
        Self { width, height, rgba }
    }

    fn blend(&mut self, x: i32, y: i32, c: [u8; 4]) {
        if x < 0 || y < 0 || x as usize >= self.width || y as usize >= self.height {
            return;
        }
        let i = (y as usize * self.width + x as usize) * 4;
        let a = c[3] as u32;
        for (dst, &src) in self.rgba[i..i + 3].iter_mut().zip(&c[..3]) {
            *dst = ((src as u32 * a + *dst as u32 * (255 - a)) / 255) as u8;
        }
        self.rgba[i + 3] = 255;
    }

    fn disc(&mut self, c: Vec2, r: f32, colour: [u8; 4]) {
        let (x0, x1, y0, y1) = ((c.x - r) as i32, (c.x + r) as i32 + 1, (c.y - r) as i32, (c.y + r) as i32 + 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                if Vec2::new(x as f32 + 0.5, y as f32 + 0.5).distance(c) <= r {
                    self.blend(x, y, colour);
                }
            }
        }
    }

    fn ring(&mut self, c: Vec2, r: f32, colour: [u8; 4]) {
        let steps = (r * 8.0).max(12.0) as usize;
        for k in 0..steps {
            let t = k as f32 / steps as f32 * std::f32::consts::TAU;
            self.blend((c.x + r * t.cos()) as i32, (c.y + r * t.sin()) as i32, colour);
        }
    }

    fn line(&mut self, a: Vec2, b: Vec2, colour: [u8; 4]) {
        let steps = a.distance(b).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let p = a.lerp(b, k as f32 / steps as f32);
            self.blend(p.x as i32, p.y as i32, colour);
        }
    }
}

const BACKGROUND: [u8; 4] = [24, 24, 28, 255];
const OUTSIDE: [u8; 4] = [40, 40, 46, 255];
const ZERO: [u8; 4] = [8, 8, 10, 255];

/// Colour of a density value on the shared log scale whose top is `top` (log10).
pub(super) fn density_colour(v: f32, top: f32) -> [u8; 4] {
    if !(v > 0.0) {
        return ZERO;
    }
    let t = (v.log10() - (top - DECADES)) / DECADES;
    let c = colorous::INFERNO.eval_continuous(t.clamp(0.0, 1.0) as f64);
    [c.r, c.g, c.b, 255]
}

/// Colour of a ratio on a diverging log scale over ±2 decades (white at 1).
fn ratio_colour(integrand: f32, density: f32) -> [u8; 4] {
    match (integrand > 0.0, density > 0.0) {
        (false, false) => ZERO,
        (true, false) => [200, 0, 0, 255], // the strategy never samples where the integrand is: bias
        _ => {
            let r = (integrand.max(1e-30) / density).log10();
            let c = colorous::RED_BLUE.eval_continuous(((2.0 - r) / 4.0).clamp(0.0, 1.0) as f64);
            [c.r, c.g, c.b, 255]
        }
    }
}

/// Colour of a chi-square residual (o − e)/√e over ±4 (white at 0, red where too many samples fell).
pub(super) fn residual_colour(r: f32) -> [u8; 4] {
    let c = colorous::RED_BLUE.eval_continuous(((4.0 - r) / 8.0).clamp(0.0, 1.0) as f64);
    [c.r, c.g, c.b, 255]
}

/// Colour of a sample's weight `f L cos / p`, relative to L_o, over ±3 decades.
fn weight_colour(relative: f32) -> [u8; 4] {
    let t = (relative.log10() + 3.0) / 6.0;
    let c = colorous::TURBO.eval_continuous(t.clamp(0.0, 1.0) as f64);
    [c.r, c.g, c.b, 235]
}

/// Draws the picture: one disk of `maps.size` pixels per switched-on heatmap, side by side (integrand, density,
/// their ratio, and the learned guide's density where there is one), on one log scale.
pub fn draw(
    ctx: &SampleContext,
    sp: &ShadingPoint,
    maps: &Maps,
    records: &[SampleRecord],
    truth: f32,
    layers: Layers,
) -> Picture {
    let s = maps.size;
    let guide = maps.guide.as_deref().filter(|_| layers.guide);
    let panels: Vec<u8> = [(layers.integrand, 0u8), (layers.density, 1), (layers.ratio, 2), (guide.is_some(), 3)]
        .into_iter()
        .filter_map(|(on, k)| on.then_some(k))
        .collect();
    let gap = 8;
    let n = panels.len().max(1);
    let mut pic = Picture::new(n * s + (n - 1) * gap, s);
    let top = maps
        .integrand
        .iter()
        .chain(&maps.density)
        .copied()
        .filter(|v| v.is_finite())
        .fold(f32::MIN_POSITIVE, f32::max)
        .log10();
    let frame = Frame::from_z(sp.n);
    let to_px = |d: Vec2, x0: usize| Vec2::new(x0 as f32 + (d.x + 1.0) * 0.5 * s as f32, (1.0 - d.y) * 0.5 * s as f32);
    for (slot, &kind) in panels.iter().enumerate() {
        let x0 = slot * (s + gap);
        for i in 0..s * s {
            let (g, p) = (maps.integrand[i], maps.density[i]);
            let c = if g.is_nan() {
                OUTSIDE
            } else {
                match kind {
                    0 => density_colour(g, top),
                    1 => density_colour(p, top),
                    2 => ratio_colour(g, p),
                    _ => density_colour(guide.map_or(0.0, |m| m[i]), top),
                }
            };
            pic.blend((x0 + i % s) as i32, (i / s) as i32, c);
        }
        let centre = to_px(Vec2::ZERO, x0);
        pic.ring(centre, s as f32 * 0.5, [160, 160, 170, 255]); // the horizon
        pic.line(centre - Vec2::X * 4.0, centre + Vec2::X * 4.0, [90, 200, 255, 255]); // n
        pic.line(centre - Vec2::Y * 4.0, centre + Vec2::Y * 4.0, [90, 200, 255, 255]);
        let wr = frame.to_local(reflect(sp.wo, sp.n));
        if sp.material.ks != Vec3::ZERO && wr.z > 0.0 {
            pic.ring(to_px(hemisphere_to_disk(wr), x0), 5.0, [120, 255, 120, 255]);
        }
        if layers.outlines {
            for &t in &ctx.scene.emitters {
                let tri = &ctx.scene.triangles[t as usize];
                if !faces(tri, sp.p) {
                    continue;
                }
                for e in 0..3 {
                    let (a, b) = (tri.v[e], tri.v[(e + 1) % 3]);
                    let steps = 48;
                    let mut last: Option<Vec2> = None;
                    for k in 0..=steps {
                        let w = frame.to_local((a.lerp(b, k as f32 / steps as f32) - sp.p).normalize_or_zero());
                        let here = (w.z > 0.0).then(|| to_px(hemisphere_to_disk(w), x0));
                        if let (Some(p), Some(q)) = (last, here) {
                            pic.line(p, q, [255, 255, 255, 200]);
                        }
                        last = here;
                    }
                }
            }
        }
        if layers.samples {
            for r in records {
                let w = frame.to_local(r.wi);
                if r.outcome == Outcome::NoSample || !(w.z > 0.0) {
                    continue;
                }
                let at = to_px(hemisphere_to_disk(w), x0);
                let colour = match r.outcome {
                    Outcome::Contributed if truth > 0.0 => {
                        weight_colour(luminance(r.contribution / r.mis_weight.max(1e-30)) / truth)
                    }
                    Outcome::Contributed => weight_colour(1.0),
                    _ => [150, 150, 150, 160],
                };
                // MIS: each technique its own marker, its size growing with the MIS weight.
                let radius = if r.mis_weight < 1.0 { 1.2 + 2.0 * r.mis_weight } else { 1.6 };
                if r.technique == 0 {
                    pic.disc(at, radius, colour);
                } else {
                    pic.ring(at, radius + 1.0, colour);
                }
            }
        }
    }
    pic
}
