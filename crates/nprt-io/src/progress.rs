//! The one progress bar style: what is counted, how far, elapsed time and ETA; and one bar over
//! a job of several stages ([`StagedBar`]), which the stages' own bars report into.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// The bars made while a [`StagedBar`] is open, with what each counts: hidden, their progress
/// read by it.
type Stages = Arc<Mutex<Vec<(String, ProgressBar)>>>;

static OPEN: Mutex<Option<Stages>> = Mutex::new(None);

/// A bar over `len` `unit`s of `what` (e.g. "generating", "views"); hidden unless `show`.
/// Callers put live figures (a loss, a rate) in its message. While a [`StagedBar`] is open
/// the bar is hidden and reports to it.
pub fn progress_bar(show: bool, len: u64, what: &str, unit: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    if let Some(stages) = OPEN.lock().unwrap_or_else(PoisonError::into_inner).as_ref() {
        let bar = ProgressBar::hidden();
        bar.set_length(len);
        let mut bars = stages.lock().unwrap_or_else(PoisonError::into_inner);
        bars.push((what.to_string(), bar.clone()));
        return bar;
    }
    styled(ProgressBar::new(len), &format!(
        "{{spinner}} {what} [{{bar:30}}] {{pos}}/{{len}} {unit} {{msg}} ({{elapsed}} elapsed, ETA {{eta}})"
    ))
}

/// Whether a [`StagedBar`] is open: the stages' own lines (a training's per-epoch losses) then
/// stay quiet, as their bars do.
pub fn staged() -> bool {
    OPEN.lock()
        .unwrap_or_else(PoisonError::into_inner)
        .is_some()
}

fn styled(bar: ProgressBar, template: &str) -> ProgressBar {
    // The template is a constant shape; only `what` and `unit` vary, and braces in them would
    // only be printed literally if escaped, so fall back to the default style rather than fail.
    if let Ok(style) = ProgressStyle::with_template(template) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// Ticks of the staged bar per estimated second of work.
const TICKS_PER_SECOND: f64 = 10.0;

/// One bar over the stages of a job (`nprt bake`: dataset, training, evaluation), each with an
/// estimate of its seconds: the bar moves through a stage as the stage's own bars (made with
/// [`progress_bar`], hidden while this one is open) move, so its ETA comes from the rates the
/// stages measure. One at a time per process; dropping it closes it.
pub struct StagedBar {
    bar: ProgressBar,
    state: Arc<Mutex<Plan>>,
    stop: Arc<AtomicBool>,
    ticker: Option<JoinHandle<()>>,
}

/// The stages, their estimates and where the job stands.
struct Plan {
    names: Vec<String>,
    seconds: Vec<f64>,
    current: usize,
    stages: Stages,
}

impl Plan {
    fn ticks(seconds: f64) -> u64 {
        (seconds.max(0.0) * TICKS_PER_SECOND).round() as u64
    }

    /// Where the job stands, in ticks, and what the current stage is doing, in words.
    fn position(&self) -> (u64, u64, String) {
        let done: f64 = self.seconds[..self.current].iter().sum();
        let total: f64 = self.seconds.iter().sum();
        let Some(here) = self.seconds.get(self.current) else {
            return (Self::ticks(total), Self::ticks(total), "done".into());
        };
        let bars = self.stages.lock().unwrap_or_else(PoisonError::into_inner);
        // The stage's last bar that has begun: a stage's bars run one after another.
        let (fraction, what) = match bars.iter().rev().find(|(_, b)| b.position() > 0) {
            Some((what, b)) => {
                let len = b.length().unwrap_or(1).max(1);
                let msg = b.message();
                let what = match msg.is_empty() {
                    true => format!("{what} {}/{len}", b.position()),
                    false => format!("{what} {}/{len} {msg}", b.position()),
                };
                ((b.position() as f64 / len as f64).min(1.0), what)
            }
            None => (0.0, String::new()),
        };
        let words = format!(
            "{}/{} {}{}{what}",
            self.current + 1,
            self.names.len(),
            self.names[self.current],
            if what.is_empty() { "" } else { ": " }
        );
        (
            Self::ticks(done + here * fraction),
            Self::ticks(total),
            words,
        )
    }
}

impl StagedBar {
    /// A bar over `stages` (name, estimated seconds), at the first; hidden unless `show`, and
    /// then the stages' own bars show as before.
    pub fn new(show: bool, stages: &[(&str, f64)]) -> StagedBar {
        let plan = Plan {
            names: stages.iter().map(|(n, _)| n.to_string()).collect(),
            seconds: stages.iter().map(|(_, s)| *s).collect(),
            current: 0,
            stages: Arc::default(),
        };
        let total = Plan::ticks(plan.seconds.iter().sum());
        let bar = match show {
            true => styled(
                ProgressBar::new(total),
                "{spinner} [{bar:30}] {percent:>3}% {msg} ({elapsed} elapsed, ETA {eta})",
            ),
            false => ProgressBar::hidden(),
        };
        if show {
            *OPEN.lock().unwrap_or_else(PoisonError::into_inner) = Some(plan.stages.clone());
        }
        let state = Arc::new(Mutex::new(plan));
        let stop = Arc::new(AtomicBool::new(false));
        let ticker = show.then(|| {
            let (bar, state, stop) = (bar.clone(), state.clone(), stop.clone());
            std::thread::spawn(move || {
                let mut shown = 0;
                while !stop.load(Ordering::Relaxed) {
                    let (pos, len, words) = state
                        .lock()
                        .unwrap_or_else(PoisonError::into_inner)
                        .position();
                    // Never backwards: a stage's next bar starts at zero.
                    shown = pos.max(shown).min(len);
                    bar.set_length(len);
                    bar.set_position(shown);
                    bar.set_message(words);
                    std::thread::sleep(Duration::from_millis(200));
                }
            })
        });
        StagedBar {
            bar,
            state,
            stop,
            ticker,
        }
    }

    /// Moves to stage `index` (the stages before it done), with its bars yet to come.
    pub fn begin(&self, index: usize) {
        let mut plan = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        plan.current = index.min(plan.names.len());
        plan.stages
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clear();
    }

    /// Sets stage `index`'s estimate (seconds), as a rate measured on the way changes it.
    pub fn estimate(&self, index: usize, seconds: f64) {
        let mut plan = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(s) = plan.seconds.get_mut(index) {
            *s = seconds;
        }
    }

    /// Prints a line above the bar (or plainly, where it is hidden).
    pub fn println(&self, line: &str) {
        match self.bar.is_hidden() {
            true => println!("{line}"),
            false => self.bar.println(line),
        }
    }
}

impl Drop for StagedBar {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.ticker.take() {
            let _ = t.join();
            *OPEN.lock().unwrap_or_else(PoisonError::into_inner) = None;
        }
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_staged_bar_moves_through_each_stage_as_its_own_bars_move() {
        let staged = StagedBar::new(false, &[("data", 10.0), ("training", 30.0)]);
        // Hidden: the stages' bars are their own, and the plan still reads them.
        let plan = || staged.state.lock().unwrap().position();
        assert_eq!(plan().0, 0);
        assert_eq!(plan().1, 400);
        let views = ProgressBar::hidden();
        views.set_length(4);
        staged
            .state
            .lock()
            .unwrap()
            .stages
            .lock()
            .unwrap()
            .push(("generating".into(), views.clone()));
        views.set_position(2);
        let (pos, _, words) = plan();
        assert_eq!(pos, 50);
        assert_eq!(words, "1/2 data: generating 2/4");
        staged.begin(1);
        assert_eq!(plan().0, 100);
        staged.estimate(1, 10.0);
        staged.begin(2);
        assert_eq!(plan(), (200, 200, "done".into()));
    }
}
