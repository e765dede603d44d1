//! What a run tells as it goes: each stage announced with the time so far, and each stage's
//! wall time kept in the output folder (stage-times.json) for the report, surviving resumes.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;

/// The run's stages as they pass.
pub struct StageLog {
    start: Instant,
    file: PathBuf,
    /// Seconds per stage in the order the stages first ran, as the invocation that last did
    /// each one's work measured them.
    pub times: Vec<(String, f64)>,
    current: Option<(String, Instant)>,
}

impl StageLog {
    /// A log whose times live in `out`/stage-times.json (read back if a run left one).
    pub fn open(out: &Path) -> Result<StageLog> {
        let file = out.join("stage-times.json");
        // Read back as input: the report prints these.
        let times = match std::fs::read(&file) {
            Ok(bytes) => crate::readback::stage_times(&bytes, &file)?,
            Err(_) => Vec::new(),
        };
        Ok(StageLog {
            start: Instant::now(),
            file,
            times,
            current: None,
        })
    }

    /// Announces stage `what`, filed under `name`.
    pub fn begin(&mut self, name: &str, what: &str) {
        println!(
            "\n== {what} ({:.0} s so far)",
            self.start.elapsed().as_secs_f64()
        );
        self.current = Some((name.to_string(), Instant::now()));
    }

    /// Ends the stage under way. Its time is recorded when it `worked`: a stage whose result
    /// was cached keeps the time its earlier run recorded.
    pub fn end(&mut self, worked: bool) -> Result<()> {
        let Some((name, t)) = self.current.take() else {
            return Ok(());
        };
        let secs = t.elapsed().as_secs_f64();
        match self.times.iter_mut().find(|(n, _)| *n == name) {
            Some((_, t)) if worked => *t = secs,
            Some(_) => return Ok(()),
            None => self.times.push((name, secs)),
        }
        nprt_io::write_file(&self.file, serde_json::to_vec_pretty(&self.times)?)
    }

    /// Seconds since the log was opened.
    pub fn elapsed(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }
}
