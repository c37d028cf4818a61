//! `tessera regress`: run a regression suite's cases (or one shard of them), judge each
//! against its reference, print a table with the worst case first; exit 0 when every case
//! passes. A case that fails, or cannot be run, does not stop the others.

use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use tessera::error::Result;
use tessera::regress::{CaseResult, Shard, Suite, run_case};

/// `tessera regress`'s arguments.
#[derive(clap::Args)]
pub struct RegressArgs {
    /// The suite file (TOML; `[[case]]` tables, see src/regress.rs).
    suite: PathBuf,
    /// Run shard i of N only (0 <= i < N): case k belongs to shard k mod N.
    #[arg(long, value_name = "i/N", default_value = "0/1")]
    shard: Shard,
    /// Print nothing but the table and errors.
    #[arg(short, long)]
    quiet: bool,
}

/// The sort key of a case's outcome: errors first, then failures, then by relMSE, largest first.
fn badness(result: &CaseResult) -> (u8, f64) {
    match result {
        Err(_) => (0, 0.0),
        Ok(v) if !v.passes() => (1, -v.metrics.relmse),
        Ok(v) => (2, -v.metrics.relmse),
    }
}

/// Run `tessera regress`.
pub fn run(args: &RegressArgs) -> Result<ExitCode> {
    let suite = Suite::load(&args.suite)?;
    let cases = suite.shard(args.shard);
    let bar = if args.quiet { ProgressBar::hidden() } else { ProgressBar::new(cases.len() as u64) };
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} cases [{elapsed_precise}, ETA {eta}] {msg}")
            .expect("valid template"),
    );
    let mut outcomes = Vec::with_capacity(cases.len());
    for case in &cases {
        bar.set_message(case.name.clone());
        let start = Instant::now();
        let result = run_case(case);
        outcomes.push((case.name.as_str(), result, start.elapsed().as_secs_f64()));
        bar.inc(1);
    }
    bar.finish_and_clear();
    outcomes.sort_by(|a, b| badness(&a.1).partial_cmp(&badness(&b.1)).unwrap_or(std::cmp::Ordering::Equal));
    println!(
        "{}: {} of {} cases (shard {}/{})",
        args.suite.display(),
        cases.len(),
        suite.cases.len(),
        args.shard.index,
        args.shard.count
    );
    println!(
        "  {:<6} {:<24} {:>11} {:>9} {:>9} {:>8} {:>8}",
        "", "case", "relMSE", "FLIP", "Z pass %", "mean z", "seconds"
    );
    let mut failed = 0;
    for (name, result, seconds) in &outcomes {
        match result {
            Ok(v) => {
                let (accepted, mean_z) = v.z.as_ref().map_or((String::from("-"), String::from("-")), |z| {
                    let worst = z.mean_z.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    (format!("{:.3}", 100.0 * z.accepted_fraction), format!("{worst:.2}"))
                });
                let verdict = if v.passes() { "PASS" } else { "FAIL" };
                println!(
                    "  {verdict:<6} {name:<24} {:>11.4e} {:>9.5} {accepted:>9} {mean_z:>8} {seconds:>8.1}",
                    v.metrics.relmse, v.metrics.mean_flip
                );
                if !v.passes() {
                    failed += 1;
                    println!("         {}", v.failures.join("; "));
                }
            }
            Err(e) => {
                failed += 1;
                println!("  {:<6} {name:<24} {e}", "ERROR");
            }
        }
    }
    println!("{}: {failed} of {} cases failed", if failed == 0 { "PASS" } else { "FAIL" }, outcomes.len());
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
