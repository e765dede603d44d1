//! A run's side of a live run (`nprt view --train`): between steps it tells the watcher where
//! it stands, saves or lengthens itself when asked, hands over its model when the watcher wants
//! one (at most every [`PUBLISH_SECS`] of training), and waits while paused, its time not
//! counted.

use std::time::Duration;

use anyhow::Result;

use crate::optimiser::EngineSteps;
use crate::training::live::{Asks, LiveRun, PUBLISH_SECS};
use crate::training::objective::Objective;
use crate::training::run::Run;
use crate::training::training_loop::run_key;

impl<O: Objective> Run<'_, O> {
    /// Whether a live run's watcher asked the run to stop.
    pub(super) fn stopped(&self) -> bool {
        self.live.is_some_and(|l| l.stopping())
    }

    /// Serves a live run's watcher between steps: where the run stands, a save or a longer
    /// budget asked for, the model when the watcher wants one (at most every [`PUBLISH_SECS`] of
    /// training), and a pause (the model
    /// published first, the time paused not counted). `at` is the epoch, its batches and the
    /// steps per loss row, as [`Self::settle`] takes them.
    pub(super) fn attend(
        &mut self,
        live: &LiveRun,
        net: &mut O::Net,
        steps: &mut dyn EngineSteps<O::Net, O::Batch>,
        at: (usize, usize, u64),
    ) -> Result<()> {
        let (epoch, total, row_every) = at;
        let mut published = false;
        loop {
            let asks = self.report(live);
            if asks.extend_minutes > 0.0 {
                self.extend(asks.extend_minutes);
            }
            let pausing = live.pausing();
            let since = self.ck.state.seconds - self.published_at;
            let due = !published && (pausing || asks.model && since >= PUBLISH_SECS);
            if asks.save || due {
                self.settle(steps, epoch, total, row_every)?;
                steps.store(net);
            }
            if asks.save {
                self.save(net, steps)?;
                let step = self.ck.state.step;
                live.report(|s| s.saved_at = Some(step));
            }
            if due {
                self.publish(live, net);
                published = true;
            }
            if !pausing {
                return Ok(());
            }
            self.idle += live.wait_paused(Duration::from_millis(100));
        }
    }

    /// Tells a live run's watcher where the run stands; returns what the watcher asked.
    pub(super) fn report(&self, live: &LiveRun) -> Asks {
        let (state, history) = (self.ck.state, &self.ck.history);
        live.report(|s| {
            s.step = state.step;
            s.samples = state.samples;
            s.seconds = state.seconds;
            s.budget = self.budget();
            s.train_loss = self.guard.ema;
            s.rows
                .extend_from_slice(history.get(s.rows.len()..).unwrap_or_default());
        })
    }

    /// Hands a live run's watcher the model as it stands (`net` up to date).
    pub(super) fn publish(&mut self, live: &LiveRun, net: &O::Net) {
        let state = &self.ck.state;
        self.objective.publish(net, &self.schedule, state, live);
        self.published_at = state.seconds;
    }

    /// Lengthens the run's time budget by `minutes` (a run bounded by epochs stays so), and
    /// the key its checkpoint resumes under with it: `nprt train --minutes` of the new length
    /// (the sum, as the watcher adds it) continues it.
    pub(super) fn extend(&mut self, minutes: f64) {
        if let Some(before) = self.schedule.minutes {
            self.schedule.minutes = Some(before + minutes);
            self.ck.run = run_key(self.objective, &self.schedule);
            let budget = self.budget().expect("a run of minutes has a budget");
            self.bar.set_length(budget.ceil() as u64);
        }
    }
}
