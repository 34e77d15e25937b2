//! A whole render in one pass, with a progress bar that appears once it has taken a second and advances row by
//! row.
//!
//! One pass rather than several: each pass ends with threads waiting for its last rows, and a pixel takes its
//! samples eight at a time, so a pass whose sample count is not a multiple of eight leaves lanes empty. The knot
//! at 256², 256 spp rendered 5% faster in one pass than in the three (122, 122 and 12 spp) that a bar advancing
//! between passes had asked for (docs/performance-history.md). The film does not depend on the split.

use illumlab::render::{Film, PassStats, Renderer};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::{Duration, Instant};

/// A render shorter than this shows no bar.
const QUIET: Duration = Duration::from_secs(1);

/// How often the bar is redrawn.
const TICK: Duration = Duration::from_millis(100);

/// Adds samples `0..spp` to every pixel of `film` on the current rayon pool, showing `label` and a bar on
/// standard error while it takes longer than a second.
pub(crate) fn render_all(renderer: &mut Renderer, film: &mut Film, spp: u32, label: &str) -> PassStats {
    let rows = u64::from(film.height.max(1));
    // Samples per pixel taken so far, summed over the rows.
    let taken = AtomicU64::new(0);
    let (finished, ticks) = mpsc::channel::<()>();
    std::thread::scope(|scope| {
        let taken = &taken;
        scope.spawn(move || {
            let start = Instant::now();
            let mut bar = None;
            // The sender is dropped when the render ends, which ends the wait at once.
            while let Err(RecvTimeoutError::Timeout) = ticks.recv_timeout(TICK) {
                if start.elapsed() < QUIET {
                    continue;
                }
                let bar = bar.get_or_insert_with(|| {
                    let template = format!("{label}{{bar:40}} {{pos}}/{{len}} spp  {{elapsed}} (eta {{eta}})");
                    let style = indicatif::ProgressStyle::with_template(&template).expect("valid template");
                    indicatif::ProgressBar::new(u64::from(spp)).with_style(style).with_elapsed(start.elapsed())
                });
                bar.set_position(taken.load(Ordering::Relaxed) / rows);
            }
            if let Some(bar) = bar {
                bar.finish_and_clear();
            }
        });
        let row_done = |n: u32| {
            taken.fetch_add(u64::from(n), Ordering::Relaxed);
        };
        let stats = renderer.render_pass_with_progress(film, 0, spp, &|| false, &row_done);
        drop(finished);
        stats
    })
}
