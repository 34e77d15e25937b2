//! How many samples per pixel one pass of a lane takes: how often the viewer sees a new frame, against how much
//! of the time goes to publishing frames and whether the eight-lane path runs (passes of fewer than four samples
//! take the one-sample path: see `render::pass`).

use std::time::Duration;

/// A pass's samples per pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PassSize {
    /// Sized by time: the first pass after a restart takes one sample per pixel, so that a new setting shows at
    /// once; later ones take, at the rate measured so far, the whole groups of eight samples (the eight-lane
    /// path's) that last [`PassSize::duration`], and at least one group where that takes at most 250 ms. Where
    /// even one group would take longer (a slow estimator, a huge image), a pass takes what fits in 250 ms, at
    /// least one sample.
    #[default]
    Auto,
    /// This many, every pass.
    Fixed(u32),
}

/// Auto passes last at least this long...
const SHORTEST: Duration = Duration::from_millis(30);
/// ...and at most this long.
const LONGEST: Duration = Duration::from_millis(250);
/// The samples of one pixel that the eight-lane path takes at once.
const GROUP: u32 = crate::render::LANES as u32;

impl PassSize {
    /// How long the next auto pass should take, after `elapsed` of rendering: an eighth of it, within 30 to
    /// 250 ms. The image changes less and less as it converges, so frames may come less often: after 8 s at
    /// 4 per second.
    pub fn duration(elapsed: Duration) -> Duration {
        (elapsed / 8).clamp(SHORTEST, LONGEST)
    }

    /// The next pass's samples per pixel, for a lane that has taken `spp` samples per pixel in `passes` passes and
    /// `elapsed` of wall-clock time.
    pub fn count(self, passes: u32, spp: u32, elapsed: Duration) -> u32 {
        match self {
            PassSize::Fixed(n) => n.max(1),
            PassSize::Auto if passes == 0 || spp == 0 || elapsed.is_zero() => 1,
            PassSize::Auto => {
                let per_spp = elapsed.as_secs_f64() / spp as f64;
                let fits = |d: Duration| (d.as_secs_f64() / per_spp).floor().clamp(1.0, 4096.0) as u32;
                match fits(Self::duration(elapsed)) {
                    n if n >= GROUP => n - n % GROUP,
                    _ if fits(LONGEST) >= GROUP => GROUP,
                    _ => fits(LONGEST),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_passes_start_with_one_sample_then_follow_the_rate() {
        let ms = Duration::from_millis;
        assert_eq!(PassSize::Auto.count(0, 0, Duration::ZERO), 1, "the first pass shows at once");
        // 20 ms per spp so far (a 512² Cornell box on one core): 30 ms would be 1 spp, but a group of eight
        // (160 ms) fits in 250 ms.
        assert_eq!(PassSize::Auto.count(1, 1, ms(20)), 8);
        // 1 ms per spp: 30 passes' worth, in whole groups of eight.
        assert_eq!(PassSize::Auto.count(1, 20, ms(20)), 24);
        // After 4 s at 1 ms per spp: 500 ms / 8 = … capped at 250 ms, 248 spp.
        assert_eq!(PassSize::Auto.count(40, 4000, ms(4000)), 248);
        // 100 ms per spp: a group would take 800 ms; 2 spp fit in 250 ms.
        assert_eq!(PassSize::Auto.count(2, 2, ms(200)), 2);
        // A slow estimator (1 s per spp) still takes one sample per pass.
        assert_eq!(PassSize::Auto.count(3, 3, ms(3000)), 1);
        assert_eq!(PassSize::Fixed(5).count(0, 0, Duration::ZERO), 5);
        assert_eq!(PassSize::Fixed(0).count(9, 9, ms(9)), 1);
    }

    #[test]
    fn passes_last_an_eighth_of_the_time_so_far_within_bounds() {
        let ms = Duration::from_millis;
        assert_eq!(PassSize::duration(ms(0)), ms(30));
        assert_eq!(PassSize::duration(ms(800)), ms(100));
        assert_eq!(PassSize::duration(ms(60_000)), ms(250));
    }
}
