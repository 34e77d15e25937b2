//! Fits the Phong LTC table (`src/sampling/phong_ltc_table.rs`) that BRDF-weighted polygon sampling uses: at each
//! node (α, θ_o) the parameters (A, B, C, T) of `M = F·R_y(θ_o + T)·[[sA, 0, sB], [0, sC, 0], [0, 0, 1]]`
//! (see `src/sampling/ltc.rs`) that minimise `∫ q²/D dω`, q the Phong lobe times the cosine normalised by its mass
//! Z. That integral is the relative second moment of q/D: the variance, relative to the ideal, of sampling q with
//! the LTC D, which is what the sampler pays for a poor fit. Heitz et al.'s procedure (Nelder–Mead from the
//! previous node's fit, the BRDF's average direction as the start), with this objective in place of their L³
//! error, written from the paper.
//!
//! The objective is estimated with fixed stratified lobe samples (common random numbers, so that it is a smooth
//! function of the parameters): `∫ q²/D = E_g[g (ω·n)⁺² / (Z² D(ω))]`, g the Phong lobe density, which covers q.
//!
//! `cargo run --release --example fit_phong_ltc` rewrites the table and prints each node's fitted objective
//! against the isotropic LTC's.

use illumlab::sampling::{LobeSamples, Ltc, PhongLtcParameters};
use std::f64::consts::FRAC_PI_2;
use std::fmt::Write;

const ALPHA_COUNT: usize = 25;
const THETA_COUNT: usize = 24;
const MAX_ALPHA: f64 = 1e6;
/// The last node's view angle: 89.5°.
const MAX_THETA: f64 = 89.5 * std::f64::consts::PI / 180.0;
const STRATA: usize = 96;

/// `∫ q²/D dω` for the parameters (ln A, ln C, B, T).
fn objective(s: &LobeSamples, alpha: f64, theta_o: f64, x: [f64; 4]) -> f64 {
    let p = PhongLtcParameters { a: x[0].exp(), b: x[2], c: x[1].exp(), tilt: x[3], mass: s.mass };
    Ltc::from_matrix(p.local_matrix(alpha, theta_o)).map_or(f64::INFINITY, |ltc| s.second_moment(&ltc))
}

/// Nelder–Mead (reflection 1, expansion 2, contraction ½, shrink ½) from `start` with the given steps.
fn nelder_mead(f: &dyn Fn([f64; 4]) -> f64, start: [f64; 4], step: [f64; 4], iterations: usize) -> ([f64; 4], f64) {
    let mut simplex: Vec<([f64; 4], f64)> = vec![(start, f(start))];
    for k in 0..4 {
        let mut x = start;
        x[k] += step[k];
        simplex.push((x, f(x)));
    }
    for _ in 0..iterations {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, worst) = (simplex[0].1, simplex[4].1);
        if (worst - best).abs() <= 1e-9 * best.abs() {
            break;
        }
        let centroid: [f64; 4] = std::array::from_fn(|k| simplex[..4].iter().map(|p| p.0[k]).sum::<f64>() / 4.0);
        let along = |t: f64| -> [f64; 4] { std::array::from_fn(|k| centroid[k] + t * (simplex[4].0[k] - centroid[k])) };
        let reflected = along(-1.0);
        let fr = f(reflected);
        if fr < simplex[0].1 {
            let expanded = along(-2.0);
            let fe = f(expanded);
            simplex[4] = if fe < fr { (expanded, fe) } else { (reflected, fr) };
        } else if fr < simplex[3].1 {
            simplex[4] = (reflected, fr);
        } else {
            let contracted = if fr < simplex[4].1 { along(-0.5) } else { along(0.5) };
            let fc = f(contracted);
            if fc < simplex[4].1.min(fr) {
                simplex[4] = (contracted, fc);
            } else {
                let b = simplex[0].0;
                for p in simplex.iter_mut().skip(1) {
                    p.0 = std::array::from_fn(|k| b[k] + 0.5 * (p.0[k] - b[k]));
                    p.1 = f(p.0);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    simplex[0]
}

fn main() {
    let alpha_nodes: Vec<f64> =
        (0..ALPHA_COUNT).map(|i| (MAX_ALPHA + 1.0).ln() * i as f64 / (ALPHA_COUNT - 1) as f64).collect();
    // Denser towards grazing, where the cosine cuts the lobe.
    let theta_nodes: Vec<f64> =
        (0..THETA_COUNT).map(|j| MAX_THETA * (FRAC_PI_2 * j as f64 / (THETA_COUNT - 1) as f64).sin()).collect();
    // Node by node, α major. The objective has flat valleys along which shear and tilt trade off; a small pull
    // towards the neighbours' fits (the node before along θ_o and the one below in α) keeps the parameters on one
    // branch of the valley, so that they vary smoothly and interpolate well, at no measurable cost in the fit.
    let (n_theta, mut table, mut report) = (theta_nodes.len(), Vec::<[f64; 4]>::new(), String::new());
    let mut rows = Vec::new();
    for (i, &ln_alpha) in alpha_nodes.iter().enumerate() {
        let alpha = ln_alpha.exp_m1();
        for (j, &theta) in theta_nodes.iter().enumerate() {
            let s = LobeSamples::new(alpha, theta, STRATA);
            let neighbours: Vec<[f64; 4]> =
                [(j > 0).then(|| table[i * n_theta + j - 1]), (i > 0).then(|| table[(i - 1) * n_theta + j])]
                    .into_iter()
                    .flatten()
                    .collect();
            let pull: [f64; 4] = if neighbours.is_empty() {
                [0.0; 4]
            } else {
                std::array::from_fn(|k| neighbours.iter().map(|x| x[k]).sum::<f64>() / neighbours.len() as f64)
            };
            let f = |x: [f64; 4]| objective(&s, alpha, theta, x);
            let regularised = |x: [f64; 4]| f(x) + 1e-3 * (0..4).map(|k| (x[k] - pull[k]).powi(2)).sum::<f64>();
            let starts = if neighbours.is_empty() { vec![[0.0; 4]] } else { neighbours.clone() };
            let (fit, _) = starts
                .into_iter()
                .map(|x| nelder_mead(&regularised, x, [0.1, 0.1, 0.1, 0.05], 3000))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .expect("a start");
            table.push(fit);
            let (value, isotropic) = (f(fit), f([0.0; 4]));
            rows.push([fit[0].exp(), fit[2], fit[1].exp(), fit[3], s.mass]);
            writeln!(
                report,
                "α = {alpha:>10.3}, θ_o = {:>5.2}°: ∫q²/D fitted {value:.4}, isotropic {isotropic:.4}; A {:.3} B {:.3} C {:.3} T {:.4} Z {:.4}",
                theta.to_degrees(),
                fit[0].exp(),
                fit[2],
                fit[1].exp(),
                fit[3],
                s.mass
            )
            .unwrap();
        }
        eprintln!("α = {alpha:.3}: done");
    }
    let table = rows;
    let mut out = String::new();
    writeln!(
        out,
        "//! Generated by `cargo run --release --example fit_phong_ltc`; do not edit. The Phong LTC's fitted"
    )
    .unwrap();
    writeln!(out, "//! parameters (see `ltc.rs`) at {ALPHA_COUNT} × {THETA_COUNT} nodes in (ln(α+1), θ_o).").unwrap();
    writeln!(out).unwrap();
    writeln!(out, "/// ln(α+1) at the table's nodes.").unwrap();
    writeln!(out, "pub const ALPHA_NODES: [f64; {ALPHA_COUNT}] = {alpha_nodes:?};").unwrap();
    writeln!(out, "/// θ_o (radians) at the table's nodes.").unwrap();
    writeln!(out, "pub const THETA_NODES: [f64; {THETA_COUNT}] = {theta_nodes:?};").unwrap();
    writeln!(out, "/// (A, B, C, T, Z) at each (α, θ_o) node, α major.").unwrap();
    writeln!(out, "pub static PARAMETERS: [[f64; 5]; {}] = [", table.len()).unwrap();
    for row in &table {
        writeln!(out, "    {row:?},").unwrap();
    }
    writeln!(out, "];").unwrap();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/src/sampling/phong_ltc_table.rs");
    std::fs::write(path, out).expect("write the table");
    print!("{report}");
    eprintln!("wrote {path}");
}
