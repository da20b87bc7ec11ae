//! The progress bar on stderr (indicatif), hidden when stderr is not a terminal.

use kinergy_train::anneal::{Observer, Progress};

/// A progress bar (hidden when stderr is not a terminal): annealing evaluations, clips,
/// frames.
pub struct Bar {
    bar: indicatif::ProgressBar,
    offset: u64,
    last: u64,
}

impl Bar {
    /// A bar for `total` evaluations.
    pub fn new(total: u64) -> Bar {
        Bar::counting(total, "evaluations")
    }

    /// A bar that shows nothing.
    pub fn hidden() -> Bar {
        Bar {
            bar: indicatif::ProgressBar::hidden(),
            offset: 0,
            last: 0,
        }
    }

    /// A bar for `total` things named `unit` (`clips`, `frames`), with the time left
    /// (hidden with `-q`).
    pub fn counting(total: u64, unit: &str) -> Bar {
        if super::QUIET.load(std::sync::atomic::Ordering::Relaxed) {
            return Bar::hidden();
        }
        let bar = indicatif::ProgressBar::new(total);
        bar.set_style(
            indicatif::ProgressStyle::with_template(&format!(
                "{{elapsed_precise}} [{{bar:40}}] {{pos}}/{{len}} {unit}, {{eta}} left  {{msg}}"
            ))
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        Bar {
            bar,
            offset: 0,
            last: 0,
        }
    }

    /// One more step done (for bars counting jobs, not evaluations).
    pub fn inc(&self) {
        self.bar.inc(1);
    }

    /// Done.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Observer for Bar {
    fn on_iteration(&mut self, p: &Progress) {
        let e = p.evaluations as u64;
        if e < self.last {
            // A new stage of a nested fit.
            self.offset += self.last;
        }
        self.last = e;
        self.bar.set_position(self.offset + e);
        self.bar.set_message(format!(
            "best {:.2} mm, mean {:.2} mm",
            p.best_cost * 1e3,
            p.mean_cost * 1e3
        ));
    }
}
