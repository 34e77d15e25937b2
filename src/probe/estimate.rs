//! The running estimate at the probed point: N samples of a strategy's estimator there, every direction they
//! evaluate recorded (the sink), with the estimate, its standard error, the relative variance of one sample and
//! the histogram of sample values.

use crate::math::{SampleRng, luminance, without_denormals};
use crate::render::{Outcome, SampleContext, SampleRecord, SampleSink, ShadingPoint, Strategy};
use glam::{DVec3, Vec3};
use std::time::{Duration, Instant};

/// The random streams of the probe's samples: independent of every pixel's (pixel indices are < 2³²).
const PROBE_STREAM: u64 = u64::MAX - 7;

/// Histogram of one-sample luminance values relative to the quadrature's value (or the mean where there is none):
/// bins of a tenth of a decade from 10⁻⁶ to 10⁶ times it, the ends open.
pub const HISTOGRAM_BINS: usize = 120;
pub const HISTOGRAM_DECADES: (f32, f32) = (-6.0, 6.0);

/// What N samples at the point gave.
#[derive(Clone, Debug)]
pub struct ProbeRun {
    pub strategy: Strategy,
    pub samples: u64,
    /// Samples whose value was not finite: counted, never averaged.
    pub non_finite: u64,
    sum: DVec3,
    sum_sq: DVec3,
    lum_sum: f64,
    lum_sum_sq: f64,
    /// Directions evaluated, by outcome (index of [`Outcome`] in [`OUTCOMES`]).
    pub outcomes: [u64; OUTCOMES.len()],
    /// The last `keep` records (oldest first).
    pub records: Vec<SampleRecord>,
    /// One-sample luminance values relative to `histogram_scale`, in log bins; zeros apart.
    pub histogram: Vec<u64>,
    pub histogram_zeros: u64,
    pub histogram_scale: f32,
    /// CPU time of the samples (one thread).
    pub time: Duration,
    pub rays: u64,
}

/// The outcomes in the order [`ProbeRun::outcomes`] counts them.
pub const OUTCOMES: [Outcome; 6] = [
    Outcome::Contributed,
    Outcome::NoSample,
    Outcome::BelowSurface,
    Outcome::ZeroBrdf,
    Outcome::MissedLights,
    Outcome::Occluded,
];

/// Keeps the last `keep` records and counts outcomes.
struct Recorder<'a> {
    run: &'a mut ProbeRun,
    keep: usize,
    next: usize,
}

impl SampleSink for Recorder<'_> {
    fn record(&mut self, r: SampleRecord) {
        let i = OUTCOMES.iter().position(|&o| o == r.outcome).unwrap_or(0);
        self.run.outcomes[i] += 1;
        if self.keep == 0 {
            return;
        }
        if self.run.records.len() < self.keep {
            self.run.records.push(r);
        } else {
            self.run.records[self.next] = r;
            self.next = (self.next + 1) % self.keep;
        }
    }
}

impl ProbeRun {
    /// `samples` samples of `strategy` at `sp`, sample k from its own stream of `seed`, keeping the last `keep`
    /// records. Histogram values are relative to `scale` (e.g. the quadrature's luminance; the mean if ≤ 0).
    pub fn run(
        ctx: &SampleContext,
        sp: &ShadingPoint,
        strategy: Strategy,
        samples: u64,
        seed: u64,
        keep: usize,
        scale: f32,
    ) -> Self {
        let mut run = ProbeRun {
            strategy,
            samples: 0,
            non_finite: 0,
            sum: DVec3::ZERO,
            sum_sq: DVec3::ZERO,
            lum_sum: 0.0,
            lum_sum_sq: 0.0,
            outcomes: [0; OUTCOMES.len()],
            records: Vec::with_capacity(keep.min(samples as usize * 4)),
            histogram: vec![0; HISTOGRAM_BINS],
            histogram_zeros: 0,
            histogram_scale: scale,
            time: Duration::ZERO,
            rays: 0,
        };
        let mut values = Vec::with_capacity(samples as usize);
        let start = Instant::now();
        let mut rays = 0;
        {
            let mut recorder = Recorder { run: &mut run, keep, next: 0 };
            // Under the flags a render's samples are taken with (and timed alike).
            without_denormals(|| {
                for k in 0..samples {
                    let mut rng = SampleRng::new(seed, PROBE_STREAM, k);
                    values.push(strategy.estimate(ctx, sp, &mut rng, &mut rays, &mut recorder));
                }
            });
            // Oldest first.
            let next = recorder.next;
            run.records.rotate_left(next);
        }
        run.time = start.elapsed();
        run.rays = rays;
        for &v in &values {
            run.add(v);
        }
        if !(run.histogram_scale > 0.0) {
            run.histogram_scale = run.mean_luminance() as f32;
        }
        run.fill_histogram(&values);
        run
    }

    fn add(&mut self, v: Vec3) {
        self.samples += 1;
        if !v.is_finite() {
            self.non_finite += 1;
            return;
        }
        let d = v.as_dvec3();
        self.sum += d;
        self.sum_sq += d * d;
        let l = luminance(v) as f64;
        self.lum_sum += l;
        self.lum_sum_sq += l * l;
    }

    /// Bins the one-sample values.
    fn fill_histogram(&mut self, values: &[Vec3]) {
        let (lo, hi) = HISTOGRAM_DECADES;
        let scale = self.histogram_scale.max(f32::MIN_POSITIVE);
        for v in values {
            let l = luminance(*v);
            if !(l > 0.0) || !l.is_finite() {
                self.histogram_zeros += 1;
                continue;
            }
            let t = ((l / scale).log10() - lo) / (hi - lo);
            let bin = ((t * HISTOGRAM_BINS as f32) as isize).clamp(0, HISTOGRAM_BINS as isize - 1) as usize;
            self.histogram[bin] += 1;
        }
    }

    /// Finite samples averaged.
    fn finite(&self) -> f64 {
        (self.samples - self.non_finite).max(1) as f64
    }

    /// The estimate (RGB).
    pub fn mean(&self) -> Vec3 {
        (self.sum / self.finite()).as_vec3()
    }

    pub fn mean_luminance(&self) -> f64 {
        self.lum_sum / self.finite()
    }

    /// The variance of one sample, per channel (unbiased).
    pub fn variance(&self) -> Vec3 {
        let n = self.finite();
        let mean = self.sum / n;
        ((self.sum_sq / n - mean * mean).max(DVec3::ZERO) * (n / (n - 1.0).max(1.0))).as_vec3()
    }

    fn luminance_variance(&self) -> f64 {
        let n = self.finite();
        let mean = self.lum_sum / n;
        (self.lum_sum_sq / n - mean * mean).max(0.0) * (n / (n - 1.0).max(1.0))
    }

    /// The estimate's standard error, per channel.
    pub fn std_error(&self) -> Vec3 {
        (self.variance() / self.finite() as f32).map(f32::sqrt)
    }

    /// The luminance's standard error.
    pub fn luminance_std_error(&self) -> f64 {
        (self.luminance_variance() / self.finite()).sqrt()
    }

    /// The 95% interval of the luminance, mean ± 1.96 standard errors.
    pub fn interval_95(&self) -> (f64, f64) {
        let (m, e) = (self.mean_luminance(), 1.96 * self.luminance_std_error());
        (m - e, m + e)
    }

    /// σ²/μ² of one sample's luminance against `truth` (the mean where truth ≤ 0): infinite where μ = 0 and σ > 0.
    pub fn relative_variance(&self, truth: f64) -> f64 {
        let mu = if truth > 0.0 { truth } else { self.mean_luminance() };
        let var = self.luminance_variance();
        if var == 0.0 { 0.0 } else { var / (mu * mu) }
    }

    /// (estimate − truth) / standard error, on luminance; 0 where both agree exactly.
    pub fn z_score(&self, truth: f64) -> f64 {
        let diff = self.mean_luminance() - truth;
        let se = self.luminance_std_error();
        if diff == 0.0 { 0.0 } else { diff / se }
    }

    /// Kish's effective sample size of the luminance values, `(Σ v)² / Σ v²`: how many samples the mean rests on
    /// (few where a rarely hit bright light dominates it, and the sample variance is then unreliable).
    pub fn effective_samples(&self) -> f64 {
        if self.lum_sum_sq > 0.0 { self.lum_sum * self.lum_sum / self.lum_sum_sq } else { 0.0 }
    }

    /// Seconds of CPU time per sample.
    pub fn seconds_per_sample(&self) -> f64 {
        self.time.as_secs_f64() / self.samples.max(1) as f64
    }

    /// Efficiency `1 / (σ²/μ² · t)`: the inverse of the relative variance after one second of sampling.
    pub fn efficiency(&self, truth: f64) -> f64 {
        1.0 / (self.relative_variance(truth) * self.seconds_per_sample())
    }

    /// Zero directions by cause.
    pub fn zero_counts(&self) -> impl Iterator<Item = (Outcome, u64)> + '_ {
        OUTCOMES.iter().copied().zip(self.outcomes).filter(|(o, _)| *o != Outcome::Contributed)
    }
}
