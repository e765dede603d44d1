//! The orderings the paper states, each judged as the demo's claims are: from the per-view (or
//! per-frame) differences between two methods on the same views and their standard error.

use nprt_eval::claim::{Claim, Verdict};
use nprt_eval::temporal::TemporalResult;
use nprt_eval::{row_name, Evaluation, MethodResult, Metrics};
use nprt_net::{Activation, Design, ModelConfig};

/// One ordering the paper states, and the paired comparisons that decide it.
pub struct Ordering {
    /// Which of the paper's tables states it.
    pub table: &'static str,
    pub statement: String,
    pub comparisons: Vec<Comparison>,
}

/// One of an ordering's comparisons: its method against `against` in `metric`.
pub struct Comparison {
    pub metric: &'static str,
    pub against: String,
    pub claim: Claim,
}

impl Ordering {
    /// Holds when every comparison holds, fails when any fails, and is otherwise not resolved
    /// by the views.
    pub fn verdict(&self) -> Verdict {
        let all = |v: Verdict| self.comparisons.iter().all(|c| c.claim.verdict == v);
        if self
            .comparisons
            .iter()
            .any(|c| c.claim.verdict == Verdict::Fails)
        {
            Verdict::Fails
        } else if !self.comparisons.is_empty() && all(Verdict::Holds) {
            Verdict::Holds
        } else {
            Verdict::Unresolved
        }
    }

    /// Which comparisons gave which verdict, with the differences of those that did not hold:
    /// "holds in L1, dSSIM; not resolved in L2 (+0.0029 ± 0.0022)". The opponent is named
    /// where the ordering has several.
    pub fn breakdown(&self) -> String {
        let several = self
            .comparisons
            .iter()
            .any(|c| c.against != self.comparisons[0].against);
        [Verdict::Holds, Verdict::Fails, Verdict::Unresolved]
            .into_iter()
            .filter_map(|v| {
                let of: Vec<String> = self
                    .comparisons
                    .iter()
                    .filter(|c| c.claim.verdict == v)
                    .map(|c| {
                        let vs = if several {
                            format!(" vs {}", c.against)
                        } else {
                            String::new()
                        };
                        let by = match v {
                            Verdict::Holds => String::new(),
                            _ => format!(" ({})", c.claim.paired.spread()),
                        };
                        format!("{}{vs}{by}", c.metric)
                    })
                    .collect();
                (!of.is_empty()).then(|| format!("{} in {}", v.word(), of.join(", ")))
            })
            .collect::<Vec<_>>()
            .join("; ")
    }
}

/// Table 2's four runs: the baseline and the PRT-inspired design, each with ReLU and with SIREN
/// transport layers, in the paper's column order.
pub fn ablation_configs() -> [ModelConfig; 4] {
    [
        (Design::Baseline, Activation::Relu),
        (Design::Baseline, Activation::Siren),
        (Design::Prt, Activation::Relu),
        (Design::Prt, Activation::Siren),
    ]
    .map(|(d, a)| ModelConfig::new(d, Some(a)))
}

/// Table 2 and Table 5 compare in the paper's two figures: the log-L1 loss and the RMSE.
const LOSS_AND_RMSE: [usize; 2] = [Metrics::LOG_L1, Metrics::RMSE];

/// `a` beats each of `others` in each of `metrics`, per view.
fn beats_all(a: &MethodResult, others: &[&MethodResult], metrics: &[usize]) -> Vec<Comparison> {
    others
        .iter()
        .flat_map(|b| {
            metrics.iter().map(move |&k| Comparison {
                metric: Metrics::NAMES[k],
                against: b.name.clone(),
                claim: Claim::beats(a, b, k),
            })
        })
        .collect()
}

/// Table 2's orderings: SIREN helps the PRT-inspired design and not the baseline; PRT-inspired
/// (S) is lowest and baseline (S) highest. Empty unless all four runs were scored.
pub fn table2(rows: &[MethodResult]) -> Vec<Ordering> {
    let find = |c: &ModelConfig| rows.iter().find(|m| m.name == row_name(c));
    let [Some(br), Some(bs), Some(pr), Some(ps)] = ablation_configs().map(|c| find(&c)) else {
        return Vec::new();
    };
    let ordering = |statement: &str, comparisons| Ordering {
        table: "Table 2",
        statement: statement.into(),
        comparisons,
    };
    vec![
        ordering(
            "SIREN helps the PRT-inspired design",
            beats_all(ps, &[pr], &LOSS_AND_RMSE),
        ),
        ordering(
            "SIREN does not help the baseline (ReLU is lower)",
            beats_all(br, &[bs], &LOSS_AND_RMSE),
        ),
        ordering(
            "PRT-inspired (S) is lowest",
            beats_all(ps, &[pr, br, bs], &LOSS_AND_RMSE),
        ),
        ordering(
            "baseline (S) is highest",
            [br, pr, ps]
                .iter()
                .flat_map(|a| beats_all(a, &[bs], &LOSS_AND_RMSE))
                .collect(),
        ),
    ]
}

/// Table 5's orderings: D/S lowest of the four designs, and the paper's order of the other
/// three (albedo ≤ PRT-inspired < baseline).
pub fn table5(e: &Evaluation) -> Vec<Ordering> {
    let [b, p, a, ds] = Design::PAPER.map(|d| e.method(&row_name(&ModelConfig::new(d, None))));
    let (Some(b), Some(p), Some(a), Some(ds)) = (b, p, a, ds) else {
        return Vec::new();
    };
    vec![
        Ordering {
            table: "Table 5",
            statement: "D/S is lowest of the four designs".into(),
            comparisons: beats_all(ds, &[a, p, b], &LOSS_AND_RMSE),
        },
        Ordering {
            table: "Table 5",
            statement: "albedo ≤ PRT-inspired < baseline".into(),
            comparisons: [(a, p), (p, b)]
                .iter()
                .flat_map(|(x, y)| beats_all(x, &[y], &LOSS_AND_RMSE))
                .collect(),
        },
    ]
}

/// Every ordering this module judges: Table 2's (from its scored runs), Table 5's and Table 6's
/// (from the evaluation), in that order.
pub fn all(e: &Evaluation, ablation: &[MethodResult]) -> Vec<Ordering> {
    [table2(ablation), table5(e), table6(e)]
        .into_iter()
        .flatten()
        .collect()
}

/// The rows Table 6 sets D/S (`ds`) against on the test views: path tracing of its cost with
/// and without OIDN, Deep Shading, SH PRT 9 and 25 (where the evaluation has them).
pub fn test_view_competitors(ds: &MethodResult) -> [String; 5] {
    let pt = ds.equal_time.clone().unwrap_or_default();
    [
        pt.clone(),
        format!("{pt} + OIDN"),
        "deep-shading".into(),
        "sh-prt-9".into(),
        "sh-prt-25".into(),
    ]
}

/// Table 6's ordering, one per competitor: D/S ahead of it in each of Table 6's metrics, on the
/// test views (path tracing of D/S's cost with and without OIDN, Deep Shading, SH PRT 9 and 25)
/// and, for the radiance caches that train online, along the camera path per frame.
pub fn table6(e: &Evaluation) -> Vec<Ordering> {
    let Some(ds) = e.method(&row_name(&ModelConfig::new(Design::Dsep, None))) else {
        return Vec::new();
    };
    let table6 = Metrics::TABLE6;
    let mut out: Vec<Ordering> = test_view_competitors(ds)
        .iter()
        .filter_map(|n| e.method(n))
        .map(|other| Ordering {
            table: "Table 6",
            statement: format!("D/S is ahead of {} on the test views", other.name),
            comparisons: beats_all(ds, &[other], &table6),
        })
        .collect();
    let Some(t) = &e.temporal else {
        return out;
    };
    let Some(ds_path) = t.method(&ds.name) else {
        return out;
    };
    for cache in ["nrc", "nrc-cache"].iter().filter_map(|n| t.method(n)) {
        out.push(Ordering {
            table: "Table 6",
            statement: format!("D/S is ahead of {} along the camera path", cache.name),
            comparisons: table6
                .iter()
                .map(|&k| Comparison {
                    metric: Metrics::NAMES[k],
                    against: cache.name.clone(),
                    claim: per_frame(ds_path, cache, k),
                })
                .collect(),
        });
    }
    out
}

/// "`a` beats `b` in metric `k`", judged on their frames along the camera path.
fn per_frame(a: &TemporalResult, b: &TemporalResult, k: usize) -> Claim {
    let values =
        |m: &TemporalResult| -> Vec<f64> { m.per_frame.iter().map(|f| f.values()[k]).collect() };
    Claim::lower(
        (&a.name, &values(a)),
        (&b.name, &values(b)),
        Metrics::NAMES[k],
        "frame",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use nprt_eval::Family;

    /// A method whose per-view log-L1 and RMSE are `values`.
    fn method(name: &str, values: &[f64]) -> MethodResult {
        let per_view: Vec<Metrics> = values
            .iter()
            .map(|&v| Metrics {
                rmse: v,
                log_l1: v,
                ..Metrics::default()
            })
            .collect();
        MethodResult {
            mean: Metrics::mean(&per_view),
            per_view,
            ..MethodResult::new(name, Family::NeuralPrt, None)
        }
    }

    fn names() -> [String; 4] {
        ablation_configs().map(|c| row_name(&c))
    }

    #[test]
    fn the_papers_ablation_order_holds_and_a_swap_fails() {
        let [br, bs, pr, ps] = names();
        let views = |level: f64| [level, level * 1.5, level * 0.8, level * 1.2];
        // The paper's order: PRT (S) < PRT (R) < baseline (R) < baseline (S), on every view.
        let rows = [
            method(&br, &views(3.0)),
            method(&bs, &views(4.0)),
            method(&pr, &views(2.0)),
            method(&ps, &views(1.0)),
        ];
        let orderings = table2(&rows);
        assert_eq!(orderings.len(), 4);
        for o in &orderings {
            assert_eq!(o.verdict(), Verdict::Holds, "{}", o.statement);
        }
        // SIREN hurting the PRT-inspired design fails the first and third orderings only.
        let swapped = [
            method(&br, &views(3.0)),
            method(&bs, &views(4.0)),
            method(&pr, &views(1.0)),
            method(&ps, &views(2.0)),
        ];
        let verdicts: Vec<Verdict> = table2(&swapped).iter().map(|o| o.verdict()).collect();
        assert_eq!(
            verdicts,
            [
                Verdict::Fails,
                Verdict::Holds,
                Verdict::Fails,
                Verdict::Holds
            ]
        );
    }

    #[test]
    fn noise_leaves_an_ordering_unresolved_and_a_missing_run_leaves_none() {
        let [br, bs, pr, ps] = names();
        // PRT (S) and PRT (R) differ by ±0.5 from view to view around the same mean.
        let rows = [
            method(&br, &[3.0; 4]),
            method(&bs, &[4.0; 4]),
            method(&pr, &[1.0, 2.0, 1.0, 2.0]),
            method(&ps, &[2.0, 1.0, 2.0, 1.0]),
        ];
        let first = &table2(&rows)[0];
        assert_eq!(
            first.verdict(),
            Verdict::Unresolved,
            "{}",
            first.comparisons[0].claim.text
        );
        assert_eq!(
            first.breakdown(),
            "not resolved in log-L1 (+0.0000 ± 0.5774), RMSE (+0.0000 ± 0.5774)"
        );
        assert!(table2(&rows[..3]).is_empty());
    }

    /// Table 5 compares the paper's four designs by name: a design beyond them (a fifth row,
    /// listed first) neither hides its orderings nor enters them.
    #[test]
    fn table5_judges_the_papers_four_beside_a_fifth_design() {
        let row = |d: Design, level: f64| {
            let name = row_name(&ModelConfig::new(d, None));
            method(&name, &[level, level * 1.5, level * 0.8, level * 1.2])
        };
        let fifth = method("dsep-wide", &[0.1; 4]);
        let methods = vec![
            fifth,
            row(Design::Baseline, 4.0),
            row(Design::Prt, 3.0),
            row(Design::Albedo, 2.0),
            row(Design::Dsep, 1.0),
        ];
        let mut evaluation: Evaluation = serde_json::from_value(serde_json::json!({
            "data": "data", "scene": "builtin:room", "test_views": 4, "resolution": [8, 8],
            "foreground_pixels": 64, "equal_time_spp": 1, "methods": [], "timing_res": 8,
            "timings": [], "denoiser": "none", "cpu_threads": 1,
        }))
        .unwrap();
        evaluation.methods = methods;
        let orderings = table5(&evaluation);
        assert_eq!(orderings.len(), 2);
        for o in &orderings {
            assert_eq!(o.verdict(), Verdict::Holds, "{}", o.statement);
            assert!(o
                .comparisons
                .iter()
                .all(|c| !c.claim.text.contains("dsep-wide")));
        }
    }
}
