//! The paper's Table 1 beside ours: skill coverage at the end of training, mean ± std over the
//! paper's 10 agents per cell (SPEC §6.1), embedded from `data/paper/table1.csv`, and the effect
//! sizes on both sides. With 3 runs a side no Mann–Whitney p can fall below 0.05, so whether a
//! variant is as much worse as in the paper is read from the effect sizes: Cohen's d needs only
//! mean ± std, so it is the one both sides have; Cliff's δ is ours only.

use std::fmt::Write as _;

use super::csv_field;
use super::stats::{Summary, cohens_d};
use super::tables::CoverageCell;
use crate::{Result, StudyError};

/// The paper's Table 1 as CSV: `env,variant,n,mean,std`, our environment and variant names.
const TABLE1: &str = include_str!("../../../../data/paper/table1.csv");

/// One cell of the paper's Table 1.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperCell {
    /// Environment, as this workspace names it.
    pub env: String,
    /// Variant, as the study manifests name it.
    pub variant: String,
    /// Mean ± std over the paper's agents (minimum and maximum unknown: the mean).
    pub summary: Summary,
}

/// The paper's Table 1 from its CSV text; a line that does not parse is an error naming it.
fn parse(text: &str) -> Result<Vec<PaperCell>, String> {
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let bad = || format!("data/paper/table1.csv: cannot read {line:?}");
            let fields: Vec<&str> = line.split(',').collect();
            let [env, variant, n, mean, std] = fields[..] else {
                return Err(bad());
            };
            let (n, mean, std) = (
                n.parse().map_err(|_| bad())?,
                mean.parse().map_err(|_| bad())?,
                std.parse().map_err(|_| bad())?,
            );
            Ok(PaperCell {
                env: env.to_owned(),
                variant: variant.to_owned(),
                summary: Summary {
                    n,
                    mean,
                    std,
                    min: mean,
                    max: mean,
                },
            })
        })
        .collect()
}

/// The paper's Table 1; an embedded table that does not parse (a damaged build) is
/// [`StudyError::Failed`] naming the line, never an empty table that would drop the comparison.
pub fn table1() -> Result<Vec<PaperCell>> {
    parse(TABLE1).map_err(StudyError::failed)
}

/// One row of the comparison: our cell and the paper's, with both sides' Cohen's d against
/// their own reference variant.
struct Row<'a> {
    ours: &'a CoverageCell,
    paper: &'a PaperCell,
    paper_d: Option<f64>,
}

fn rows<'a>(
    cells: &'a [CoverageCell],
    paper: &'a [PaperCell],
    reference: Option<&str>,
) -> Vec<Row<'a>> {
    cells
        .iter()
        .filter_map(|ours| {
            let find = |variant: &str| {
                paper
                    .iter()
                    .find(|p| p.env == ours.env && p.variant == variant)
            };
            let cell = find(&ours.variant)?;
            let paper_d = reference
                .filter(|r| *r != ours.variant)
                .and_then(find)
                .and_then(|r| cohens_d(&cell.summary, &r.summary));
            Some(Row {
                ours,
                paper: cell,
                paper_d,
            })
        })
        .collect()
}

fn number(value: Option<f64>, digits: usize) -> String {
    value.map_or_else(|| "–".to_owned(), |v| format!("{v:.digits$}"))
}

/// The smallest p, 1 / C(n₁ + n₂, n₁), as that fraction: "1/20", "1/184756".
fn smallest_p(min_p: Option<f64>) -> String {
    min_p
        .filter(|p| *p > 0.0)
        .map_or_else(|| "–".to_owned(), |p| format!("1/{:.0}", 1.0 / p))
}

/// The comparison as Markdown and CSV, `None` when no cell of ours is one of the paper's.
pub fn comparison(
    cells: &[CoverageCell],
    reference: Option<&str>,
) -> Result<Option<(String, String)>> {
    let paper = table1()?;
    let rows = rows(cells, &paper, reference);
    if rows.is_empty() {
        return Ok(None);
    }
    let mut md = String::from(
        "| environment | variant | ours | paper | ours − paper | Cohen's d, ours | Cohen's d, paper | Cliff's δ, ours | smallest p possible |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "env,variant,n,mean,std,paper_n,paper_mean,paper_std,cohens_d,paper_cohens_d,cliffs_delta,min_p\n",
    );
    for Row {
        ours,
        paper,
        paper_d,
    } in &rows
    {
        let (s, p) = (&ours.summary, &paper.summary);
        let delta = ours.test.map(|t| t.delta);
        let min_p = ours.test.map(|t| t.min_p);
        let _ = writeln!(
            md,
            "| {} | {} | {:.2} ± {:.2} (n = {}) | {:.2} ± {:.2} (n = {}) | {:+.2} | {} | {} | {} | {} |",
            ours.env,
            ours.variant,
            s.mean,
            s.std,
            s.n,
            p.mean,
            p.std,
            p.n,
            s.mean - p.mean,
            number(ours.d, 2),
            number(*paper_d, 2),
            number(delta, 2),
            smallest_p(min_p),
        );
        let _ = writeln!(
            csv,
            "{},{},{},{:.4},{:.4},{},{},{},{},{},{},{}",
            csv_field(&ours.env),
            csv_field(&ours.variant),
            s.n,
            s.mean,
            s.std,
            p.n,
            p.mean,
            p.std,
            ours.d.map_or(String::new(), |d| format!("{d:.4}")),
            paper_d.map_or(String::new(), |d| format!("{d:.4}")),
            delta.map_or(String::new(), |d| format!("{d:.4}")),
            min_p.map_or(String::new(), |p| p.to_string()),
        );
    }
    let _ = write!(
        md,
        "\nThe paper's Table 1 (mean ± std over its agents; SPEC §6.1, `data/paper/table1.csv`) beside \
         ours. Cohen's d: the reference's mean minus the variant's over the pooled sample standard \
         deviation, on each side against its own `{}` (positive: the variant is lower; – where \
         undefined: a group of one run, or no spread in either group). Cliff's δ: over every pair of our runs, the share where the \
         reference is higher minus the share where the variant is. Smallest p possible: the least \
         exact one-sided Mann–Whitney p our run counts allow, 1 / C(n₁ + n₂, n₁); at 0.01 or more \
         the paper's significance level is out of reach and only the effect sizes compare.\n",
        reference.unwrap_or("-")
    );
    Ok(Some((md, csv)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_table_is_the_papers_seven_rows_by_six_environments() {
        let cells = parse(TABLE1).unwrap();
        assert_eq!(cells.len(), 42);
        assert!(cells.iter().all(|c| c.summary.n == 10));
        // Spot checks against SPEC §6.1.
        let get = |env: &str, variant: &str| {
            cells
                .iter()
                .find(|c| c.env == env && c.variant == variant)
                .map(|c| (c.summary.mean, c.summary.std))
        };
        assert_eq!(get("lightsout-cursor", "seads"), Some((24.94, 0.06)));
        assert_eq!(
            get("lightsout-reacher", "no-relabelling"),
            Some((16.58, 4.62))
        );
        assert_eq!(get("tileswap-reacher", "no-relabelling"), Some((3.62, 3.2)));
        assert_eq!(
            get("lightsout-jaco", "no-forward-model-relabelling"),
            Some((11.5, 3.47))
        );
        assert_eq!(get("tileswap-jaco", "more-skills"), Some((11.47, 0.41)));
        assert!(parse("env,variant,n,mean,std\nx,y,10,1.0\n").is_err());
        assert!(parse("env,variant,n,mean,std\nx,y,ten,1.0,2.0\n").is_err());
    }

    #[test]
    fn the_comparison_gives_both_sides_effect_sizes() {
        let summary = |values: &[f64]| super::super::stats::summary(values).unwrap();
        let (seads, ablated) = ([24.0, 24.5, 23.5], [17.0, 19.0, 18.0]);
        let cell = |variant: &str, values: &[f64], reference: Option<&[f64]>| CoverageCell {
            env: "lightsout-reacher".into(),
            variant: variant.into(),
            summary: summary(values),
            skills: 25,
            test: reference.and_then(|r| super::super::stats::worse_than(values, r)),
            d: reference.and_then(|r| cohens_d(&summary(values), &summary(r))),
        };
        let cells = [
            cell("seads", &seads, None),
            cell("no-relabelling", &ablated, Some(&seads)),
            cell("not-in-the-paper", &ablated, Some(&seads)),
        ];
        let (md, csv) = comparison(&cells, Some("seads")).unwrap().unwrap();
        // Ours: means 24 and 18, both sds 0.5 and 1 → pooled √((0.25·2 + 1·2) / 4) = √0.625.
        let ours = 6.0 / 0.625f64.sqrt();
        // The paper's: (24.3 − 16.58) / √((0.28² + 4.62²) / 2).
        let paper = 7.72 / ((0.28f64 * 0.28 + 4.62 * 4.62) / 2.0).sqrt();
        let row = csv
            .lines()
            .find(|l| l.starts_with("lightsout-reacher,no-relabelling,"))
            .unwrap();
        let fields: Vec<&str> = row.split(',').collect();
        assert_eq!(fields[8], format!("{ours:.4}"));
        assert_eq!(fields[9], format!("{paper:.4}"));
        assert_eq!(fields[10], "1.0000"); // every ablated run below every SEADS run
        assert_eq!(fields[11], "0.05"); // 1 / C(6, 3)
        assert_eq!(csv.lines().count(), 3, "{csv}"); // header, seads, no-relabelling
        assert!(md.contains("| lightsout-reacher | seads | 24.00 ± 0.50 (n = 3) | 24.30 ± 0.28 (n = 10) | -0.30 |"), "{md}");
        assert!(md.contains("| 1.00 | 1/20 |"), "{md}");
        assert!(comparison(&cells[2..], Some("seads")).unwrap().is_none());
    }
}
