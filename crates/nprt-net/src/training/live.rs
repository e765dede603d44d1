//! A training run watched as it goes (`nprt view --train`): the run publishes where it stands
//! and, every few seconds, its model as it is; the watcher asks it to pause, resume, save now,
//! run longer or stop. Shared between the training thread and the watcher's; nothing here
//! trains or draws.

use std::sync::{Condvar, Mutex, MutexGuard};
use std::time::Duration;

use crate::model::folder::ModelFile;
use crate::network::nprt_net::NprtNet;
use crate::training::loss_curves::LossRow;

/// Seconds of training at least between two models published (a model is published when the
/// watcher wants one, and at every pause): often enough to watch the view sharpen, rarely
/// enough that making the model's file (its level measured) and copying the weights out (on
/// the GPU kernels, reading them back) costs the steps little.
pub const PUBLISH_SECS: f64 = 2.0;

/// Where the run stands, as last published.
#[derive(Clone, Debug, Default)]
pub struct LiveStatus {
    pub step: u64,
    pub samples: u64,
    /// Seconds of training (pauses not counted).
    pub seconds: f64,
    /// The run's time budget, seconds (None: bounded by epochs).
    pub budget: Option<f64>,
    /// The training loss's running mean.
    pub train_loss: f64,
    /// The loss table's rows so far (training rows, and validation at epochs' ends).
    pub rows: Vec<LossRow>,
    pub paused: bool,
    /// The step of the last save asked for, once written.
    pub saved_at: Option<u64>,
}

impl LiveStatus {
    /// Training samples a second so far.
    pub fn samples_per_sec(&self) -> f64 {
        self.samples as f64 / self.seconds.max(1e-9)
    }
}

/// What the watcher asked for since the run last looked.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Asks {
    pub save: bool,
    /// Minutes to add to the run's time budget.
    pub extend_minutes: f64,
    /// The watcher wants a newer model (asked until one is published).
    pub model: bool,
}

#[derive(Default)]
struct Shared {
    status: LiveStatus,
    asks: Asks,
    pause: bool,
    stop: bool,
    wanted: bool,
    /// The newest model and how many have been published.
    model: Option<(ModelFile, NprtNet)>,
    published: u64,
}

/// The channel between a run and its watcher.
#[derive(Default)]
pub struct LiveRun {
    shared: Mutex<Shared>,
    /// Wakes a paused run when it is resumed or stopped.
    wake: Condvar,
}

impl LiveRun {
    fn lock(&self) -> MutexGuard<'_, Shared> {
        self.shared.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Where the run stands.
    pub fn status(&self) -> LiveStatus {
        self.lock().status.clone()
    }

    /// The newest model, if one came after the `seen`-th: its number, file and network.
    pub fn model_after(&self, seen: u64) -> Option<(u64, ModelFile, NprtNet)> {
        let s = self.lock();
        let (file, net) = s.model.as_ref().filter(|_| s.published > seen)?;
        Some((s.published, file.clone(), net.clone()))
    }

    /// Pauses (`true`) or resumes the run; its time does not count while paused.
    pub fn pause(&self, pause: bool) {
        self.lock().pause = pause;
        self.wake.notify_all();
    }

    /// Asks for a newer model, published after [`PUBLISH_SECS`] of training since the last.
    pub fn want_model(&self) {
        self.lock().wanted = true;
    }

    /// Asks for the run to be saved at its next step.
    pub fn save(&self) {
        self.lock().asks.save = true;
    }

    /// Lengthens a run with a time budget by `minutes`.
    pub fn extend(&self, minutes: f64) {
        self.lock().asks.extend_minutes += minutes;
    }

    /// Ends the run at its next step, saved as the end of its time saves it.
    pub fn stop(&self) {
        self.lock().stop = true;
        self.wake.notify_all();
    }

    /// Whether the watcher asked the run to stop.
    pub fn stopping(&self) -> bool {
        self.lock().stop
    }

    /// The run's side: records where it stands and takes what was asked since it last looked.
    pub fn report(&self, status: impl FnOnce(&mut LiveStatus)) -> Asks {
        let mut s = self.lock();
        status(&mut s.status);
        s.status.paused = s.pause && !s.stop;
        Asks {
            model: s.wanted,
            ..std::mem::take(&mut s.asks)
        }
    }

    /// The run's side: the model as it stands.
    pub fn publish(&self, file: ModelFile, net: NprtNet) {
        let mut s = self.lock();
        s.model = Some((file, net));
        s.published += 1;
        s.wanted = false;
    }

    /// The run's side: whether it is to pause now.
    pub fn pausing(&self) -> bool {
        let s = self.lock();
        s.pause && !s.stop
    }

    /// The run's side: waits while paused (at most `at_most`, so that asks are served);
    /// returns the seconds waited.
    pub fn wait_paused(&self, at_most: Duration) -> f64 {
        let start = std::time::Instant::now();
        let s = self.lock();
        if s.pause && !s.stop {
            drop(self.wake.wait_timeout(s, at_most));
        }
        start.elapsed().as_secs_f64()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn asks_are_taken_once_and_a_stop_ends_a_pause() {
        let live = LiveRun::default();
        live.save();
        live.extend(2.0);
        live.extend(0.5);
        let asks = live.report(|s| s.step = 7);
        assert_eq!(
            asks,
            Asks {
                save: true,
                extend_minutes: 2.5,
                model: false
            }
        );
        assert_eq!(live.report(|_| {}), Asks::default(), "taken once");
        live.want_model();
        assert!(
            live.report(|_| {}).model && live.report(|_| {}).model,
            "until published"
        );
        assert_eq!(live.status().step, 7);
        live.pause(true);
        assert!(live.pausing());
        live.report(|_| {});
        assert!(live.status().paused);
        live.stop();
        assert!(!live.pausing() && live.stopping());
        let waited = live.wait_paused(Duration::from_secs(5));
        assert!(waited < 1.0, "a stopped run does not wait: {waited}");
        live.report(|_| {});
        assert!(!live.status().paused, "a stopped run is not paused");
    }

    #[test]
    fn a_watcher_gets_each_model_once_and_the_newest() {
        use crate::init::Init;
        use crate::model::config::ModelConfig;
        use crate::network::design::Design;
        let live = LiveRun::default();
        assert!(live.model_after(0).is_none());
        let config = ModelConfig::new(Design::Baseline, None);
        let net = config.build(&mut Init::new(0));
        let file = ModelFile::untrained(config, &net, [[0.0; 3], [1.0; 3]]);
        live.publish(file.clone(), net.clone());
        live.want_model();
        live.publish(file, net);
        assert!(
            !live.report(|_| {}).model,
            "a published model is no longer wanted"
        );
        let (n, _, _) = live.model_after(0).expect("a model");
        assert_eq!(n, 2);
        assert!(live.model_after(2).is_none(), "no newer one");
    }
}
