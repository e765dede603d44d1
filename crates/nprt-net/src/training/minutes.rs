//! Minutes of training time as a flag or a file gives them (`--minutes`, `--pause-after`,
//! `--snapshots Nm`, `nprt paper --training-minutes`, `nprt bake --minutes`, visits.csv): the
//! one range they are held to.

/// The shortest training time a flag may name, in minutes (60 ms: below a step of any network),
/// and the longest (about two years). Outside them a value is a typo, and its decimal
/// expansion (1e-300 written out) became a folder name or a report's sentence.
pub const MIN_MINUTES: f64 = 1e-3;
pub const MAX_MINUTES: f64 = 1e6;

/// Refuses minutes of training time, given by `what` (a flag), outside
/// [`MIN_MINUTES`]..=[`MAX_MINUTES`] or not finite, naming it, the value and the range.
pub fn check_minutes(m: f64, what: &str) -> Result<(), String> {
    match (MIN_MINUTES..=MAX_MINUTES).contains(&m) {
        true => Ok(()),
        false => Err(format!(
            "{what} {} is not a number of minutes from {MIN_MINUTES} to {MAX_MINUTES:e}",
            nprt_io::short_number(m)
        )),
    }
}
