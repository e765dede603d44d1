//! A claim that one method beats another, judged over the same test views with their spread.
//!
//! Sixteen held-out lightings decide little: one D/S model's L1 moved from 0.086 to 0.131
//! between two draws of them. Two methods scored on the same views move together, so the claim
//! rests on the per-view differences: their mean, and its standard error. A claim holds when the
//! mean difference is at least two standard errors in its favour, fails when it is two against,
//! and is not resolved by these views in between.

use crate::method::MethodResult;
use crate::metrics::Metrics;
use crate::temporal::TemporalResult;

/// Standard errors a difference must clear to decide a claim (about 95% two-sided).
const DECISIVE_SE: f64 = 2.0;

/// What the test views say of a claim.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    Holds,
    Fails,
    /// The difference is within two standard errors of zero: more test views would decide.
    Unresolved,
}

impl Verdict {
    pub fn mark(self) -> &'static str {
        match self {
            Verdict::Holds => "✅",
            Verdict::Fails => "❌",
            Verdict::Unresolved => "≈",
        }
    }

    pub fn word(self) -> &'static str {
        match self {
            Verdict::Holds => "holds",
            Verdict::Fails => "fails",
            Verdict::Unresolved => "not resolved",
        }
    }
}

/// The per-view differences of a metric between two methods (`a − b`): mean and standard error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Paired {
    pub diff: f64,
    /// Infinite with fewer than two views, where the spread cannot be estimated.
    pub se: f64,
    /// Views on which `a` is lower, of how many.
    pub lower_on: usize,
    pub views: usize,
}

impl Paired {
    pub fn new(a: &[f64], b: &[f64]) -> Paired {
        assert_eq!(a.len(), b.len(), "paired values of different lengths");
        let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
        let n = d.len() as f64;
        let diff = d.iter().sum::<f64>() / n.max(1.0);
        let se = if d.len() < 2 {
            f64::INFINITY
        } else {
            let var = d.iter().map(|x| (x - diff).powi(2)).sum::<f64>() / (n - 1.0);
            (var / n).sqrt()
        };
        Paired {
            diff,
            se,
            lower_on: d.iter().filter(|&&x| x < 0.0).count(),
            views: d.len(),
        }
    }

    /// The mean difference with its standard error, as reports print it: with no ± where
    /// fewer than two differences give no spread (and "none" where there are none).
    pub fn spread(&self) -> String {
        match self.views {
            0 => "none".into(),
            1 => format!("{:+.4} (one, no spread)", self.diff),
            _ => format!("{:+.4} ± {:.4}", self.diff, self.se),
        }
    }

    /// The verdict on "a is lower than b" (every metric here is an error).
    pub fn lower(&self) -> Verdict {
        if self.diff + DECISIVE_SE * self.se < 0.0 {
            Verdict::Holds
        } else if self.diff - DECISIVE_SE * self.se > 0.0 {
            Verdict::Fails
        } else {
            Verdict::Unresolved
        }
    }
}

/// One claim, in words with its figures, its verdict and the paired difference it rests on.
#[derive(Clone, Debug)]
pub struct Claim {
    pub text: String,
    pub verdict: Verdict,
    pub paired: Paired,
}

impl Claim {
    /// "`a` beats `b` in `what`", judged on their paired values (per `per`: view or frame), each
    /// given with its name.
    pub fn lower(a: (&str, &[f64]), b: (&str, &[f64]), what: &str, per: &str) -> Claim {
        let p = Paired::new(a.1, b.1);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        Claim {
            text: format!(
                "{} beats {} in {what} ({:.4} vs {:.4}; per {per} {}, lower on {} of {})",
                a.0,
                b.0,
                mean(a.1),
                mean(b.1),
                p.spread(),
                p.lower_on,
                p.views
            ),
            verdict: p.lower(),
            paired: p,
        }
    }

    /// "`a` beats `b` in `metric`", judged on their per-view values.
    pub fn beats(a: &MethodResult, b: &MethodResult, metric: usize) -> Claim {
        let values = |m: &MethodResult| -> Vec<f64> {
            m.per_view.iter().map(|v| v.values()[metric]).collect()
        };
        Claim::lower(
            (&a.name, &values(a)),
            (&b.name, &values(b)),
            Metrics::NAMES[metric],
            "view",
        )
    }

    /// "`a` beats `b` in L1 from frame `from` on" (the frames after a lighting change), judged
    /// on their per-frame L1 over those frames.
    pub fn beats_from_frame(a: &TemporalResult, b: &TemporalResult, from: usize) -> Claim {
        let (la, lb) = (a.per_frame_l1(), b.per_frame_l1());
        Claim::lower(
            (&a.name, &la[from.min(la.len())..]),
            (&b.name, &lb[from.min(lb.len())..]),
            "L1 in the frames after the lighting change",
            "frame",
        )
    }

    /// "`a` flickers less than `b`": judged on their temporal errors over the same frame pairs.
    pub fn steadier(a: &TemporalResult, b: &TemporalResult) -> Claim {
        let p = Paired::new(&a.per_pair, &b.per_pair);
        Claim {
            text: format!(
                "{} flickers less than {} along the camera path (temporal error {:.4} vs {:.4}; per frame pair {}, lower on {} of {})",
                a.name, b.name, a.temporal_error, b.temporal_error, p.spread(), p.lower_on, p.views
            ),
            verdict: p.lower(),
            paired: p,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_consistent_difference_decides_even_when_views_vary_a_lot() {
        // The views' errors range over 10×, but a is lower by 0.01 on every one.
        let b = [0.05, 0.5, 0.1, 0.3];
        let a: Vec<f64> = b.iter().map(|x| x - 0.01).collect();
        let p = Paired::new(&a, &b);
        assert!((p.diff + 0.01).abs() < 1e-12 && p.se < 1e-12);
        assert_eq!((p.lower_on, p.views), (4, 4));
        assert_eq!(p.lower(), Verdict::Holds);
        assert_eq!(Paired::new(&b, &a).lower(), Verdict::Fails);
    }

    #[test]
    fn differences_that_change_sign_leave_the_claim_unresolved() {
        // Mean −0.005, per-view differences −0.005 ± 0.02: standard error √(0.0016/3/4).
        let b = [1.0, 1.0, 1.0, 1.0];
        let a = [0.975, 1.015, 0.975, 1.015];
        let p = Paired::new(&a, &b);
        assert!((p.diff + 0.005).abs() < 1e-12);
        assert_eq!((p.lower_on, p.views), (2, 4));
        assert!((p.se - (0.0016f64 / 12.0).sqrt()).abs() < 1e-12);
        assert_eq!(p.lower(), Verdict::Unresolved);
    }

    #[test]
    fn one_view_cannot_decide() {
        let p = Paired::new(&[0.1], &[0.9]);
        assert_eq!(p.se, f64::INFINITY);
        assert_eq!(p.lower(), Verdict::Unresolved);
    }
}
