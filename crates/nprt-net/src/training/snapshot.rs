//! Models kept as a run goes (`nprt train --snapshots 1m,2m,4m`): at each point of training
//! time or of epochs, the model's own files (weights and config, no optimiser state) in
//! `OUT/snapshots/LABEL/`, a model folder like any other, so that quality can be measured as
//! training grows (`nprt paper --snapshots`). A resumed run keeps the snapshots it has.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::model::folder::{CONFIG_FILE, WEIGHTS_FILE};
use crate::training::minutes::check_minutes;

/// The folder of a model folder that holds its snapshots.
pub const SNAPSHOTS: &str = "snapshots";

/// Most points one run keeps (each is a model's files).
pub const MAX_SNAPSHOTS: usize = 64;

/// A point of a run: minutes of training time, or epochs done.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Snapshot {
    Minutes(f64),
    Epochs(usize),
}

impl Snapshot {
    /// Its folder in the model folder `out`.
    pub fn dir(&self, out: &Path) -> PathBuf {
        out.join(SNAPSHOTS).join(self.to_string())
    }

    /// Whether a run `seconds` into its training time with `epochs` epochs done has reached it.
    pub fn reached(&self, seconds: f64, epochs: usize) -> bool {
        match *self {
            Snapshot::Minutes(m) => seconds >= m * 60.0,
            Snapshot::Epochs(e) => epochs >= e,
        }
    }

    /// Whether its model files are in `out` already (kept by an earlier part of the run): its
    /// folder lands whole ([`SnapshotPlan::take`]), and one of a build that wrote the files in
    /// place holds both (a kill between them left the weights alone).
    pub fn taken(&self, out: &Path) -> bool {
        let dir = self.dir(out);
        [WEIGHTS_FILE, CONFIG_FILE]
            .iter()
            .all(|f| dir.join(f).is_file())
    }

    /// `LIST` as `--snapshots` takes it: comma-separated points, `Nm` minutes or `N` epochs,
    /// at most [`MAX_SNAPSHOTS`], each once; in the order a run reaches them (minutes, then
    /// epochs, each ascending), whatever the order given, so that what is judged over them is
    /// the same for `2,1` as for `1,2`.
    pub fn parse_list(list: &str) -> Result<Vec<Snapshot>, String> {
        let mut points = list
            .split(',')
            .map(|p| p.trim().parse())
            .collect::<Result<Vec<Snapshot>, String>>()?;
        points.sort_by(|a, b| match (a, b) {
            (Snapshot::Minutes(x), Snapshot::Minutes(y)) => x.total_cmp(y),
            (Snapshot::Epochs(x), Snapshot::Epochs(y)) => x.cmp(y),
            (Snapshot::Minutes(_), Snapshot::Epochs(_)) => std::cmp::Ordering::Less,
            (Snapshot::Epochs(_), Snapshot::Minutes(_)) => std::cmp::Ordering::Greater,
        });
        if points.len() > MAX_SNAPSHOTS {
            return Err(format!(
                "{} snapshots; a run keeps at most {MAX_SNAPSHOTS}",
                points.len()
            ));
        }
        if let Some(p) = points.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("snapshot '{}' is given twice", p[0]));
        }
        Ok(points)
    }
}

/// The points a run (or the part of it resumed now) has still to keep.
pub struct SnapshotPlan {
    pending: Vec<Snapshot>,
}

impl SnapshotPlan {
    /// The points of `points` the model folder `out` does not hold, for a run starting at
    /// `seconds` of training time and `epochs` done. A point the run passed before this start
    /// without keeping it is left out, said on stderr: the model of now is not that point's.
    pub fn new(points: &[Snapshot], out: &Path, seconds: f64, epochs: usize) -> Self {
        let mut pending = Vec::new();
        for p in points.iter().filter(|p| !p.taken(out)) {
            if p.reached(seconds, epochs) {
                eprintln!(
                    "snapshot {p}: the run passed it before this part began (at {:.1} min, \
                     epoch {epochs}) without keeping it; it is not kept",
                    seconds / 60.0
                );
            } else {
                pending.push(*p);
            }
        }
        SnapshotPlan { pending }
    }

    /// Whether a point still to keep is reached at `seconds` and `epochs`.
    pub fn due(&self, seconds: f64, epochs: usize) -> bool {
        self.pending.iter().any(|p| p.reached(seconds, epochs))
    }

    /// Keeps the model at every point reached: `save` writes the model's files into the
    /// folder it is given, a temporary one renamed into place once both are written, so that a
    /// kill leaves a point whole or not taken (and a re-run takes it).
    pub fn take(
        &mut self,
        out: &Path,
        seconds: f64,
        epochs: usize,
        mut save: impl FnMut(&Path) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        for p in self.pending.iter().filter(|p| p.reached(seconds, epochs)) {
            nprt_io::write_folder(&p.dir(out), &mut save)?;
        }
        self.pending.retain(|p| !p.reached(seconds, epochs));
        Ok(())
    }
}

impl FromStr for Snapshot {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let refused = || {
            format!(
                "'{s}' is not a snapshot point: minutes as Nm (4m, 0.5m) or epochs as a whole \
                 number (10)"
            )
        };
        match s.strip_suffix('m') {
            Some(m) => match m.parse::<f64>() {
                Ok(m) => check_minutes(m, "snapshot")
                    .map(|()| Snapshot::Minutes(m))
                    .map_err(|e| format!("'{s}': {e}")),
                _ => Err(refused()),
            },
            None => match s.parse::<usize>() {
                Ok(e) if e > 0 => Ok(Snapshot::Epochs(e)),
                _ => Err(refused()),
            },
        }
    }
}

impl fmt::Display for Snapshot {
    /// Its label and folder name: `4m`, `0.5m`, `10` (epochs).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Snapshot::Minutes(m) => write!(f, "{m}m"),
            Snapshot::Epochs(e) => write!(f, "{e}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_parse_label_and_refuse_what_no_run_reaches() {
        let list = Snapshot::parse_list("10, 1m,2, 0.5m,16m").unwrap();
        assert_eq!(
            list,
            [
                Snapshot::Minutes(0.5),
                Snapshot::Minutes(1.0),
                Snapshot::Minutes(16.0),
                Snapshot::Epochs(2),
                Snapshot::Epochs(10)
            ]
        );
        let labels: Vec<String> = list.iter().map(|p| p.to_string()).collect();
        assert_eq!(labels, ["0.5m", "1m", "16m", "2", "10"]);
        assert_eq!(Snapshot::parse_list("2,1"), Snapshot::parse_list("1,2"));
        // Each label parses back to its point.
        assert!(list
            .iter()
            .all(|p| p.to_string().parse::<Snapshot>() == Ok(*p)));
        for bad in [
            "0m", "-1m", "nanm", "infm", "0", "1.5", "m", "4min", "1m,1m", "", "1e-300m", "1e-4m",
            "2e6m", "2,1,2",
        ] {
            assert!(Snapshot::parse_list(bad).is_err(), "{bad}");
        }
        assert!(Snapshot::Minutes(2.0).reached(120.0, 0));
        assert!(!Snapshot::Minutes(2.0).reached(119.9, 99));
        assert!(Snapshot::Epochs(3).reached(0.0, 3) && !Snapshot::Epochs(3).reached(1e9, 2));
    }
}
