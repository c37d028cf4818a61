//! `tessera regress`: run a regression suite's cases (or one shard of them), judge each
//! against its reference, write the HTML report, print a table with the worst case first; exit
//! 0 when every case passes. A case that fails, or cannot be run, does not stop the others.
//! `--gather` builds the whole suite's report from its shards' reports instead.

use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use tessera::error::Result;
use tessera::regress::report::{CaseRecord, INDEX_FILE, Outcome, Report, default_folder};
use tessera::regress::{Case, Shard, Suite, run_case};

/// Progress steps per case.
const PER_CASE: u64 = 1000;

/// `tessera regress`'s arguments.
#[derive(clap::Args)]
pub struct RegressArgs {
    /// The suite file (TOML; `[[case]]` tables, see src/regress.rs), or a folder with a suite.toml.
    suite: PathBuf,
    /// Run shard i of N only (0 <= i < N): case k belongs to shard k mod N.
    #[arg(long, value_name = "i/N", default_value = "0/1", conflicts_with = "gather")]
    shard: Shard,
    /// The report's folder [default: report, or report/shard-i-of-N for a shard].
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,
    /// Run nothing: gather these shards' report folders into one report of the whole suite.
    #[arg(long, value_name = "DIR", num_args = 1..)]
    gather: Vec<PathBuf>,
    /// Print nothing but the table and errors.
    #[arg(short, long)]
    quiet: bool,
}

/// Run `tessera regress`.
pub fn run(args: &RegressArgs) -> Result<ExitCode> {
    let suite = Suite::load(&args.suite)?;
    let label = args.suite.display().to_string();
    let folder = args.report.clone().unwrap_or_else(|| default_folder(args.shard));
    let mut report = Report::new(&folder)?;
    let cases: Vec<&Case> = if args.gather.is_empty() { suite.shard(args.shard) } else { suite.cases.iter().collect() };
    if args.gather.is_empty() {
        // The bar counts thousandths of cases, so that a long render moves it (and its ETA).
        let bar = if args.quiet { ProgressBar::hidden() } else { ProgressBar::new(PER_CASE * cases.len() as u64) };
        bar.set_style(
            ProgressStyle::with_template("{bar:30} {percent}% of {msg} [{elapsed_precise}, ETA {eta}]")
                .expect("valid template"),
        );
        for (k, case) in cases.iter().enumerate() {
            bar.set_message(format!("{} cases: {} ({} of {})", cases.len(), case.name, k + 1, cases.len()));
            let start = Instant::now();
            let base = PER_CASE * k as u64;
            let result = run_case(case, &|done, total| bar.set_position(base + PER_CASE * done / total.max(1)));
            report.add(case, &result, start.elapsed().as_secs_f64())?;
            bar.set_position(base + PER_CASE);
        }
        bar.finish_and_clear();
    } else {
        for shard_report in &args.gather {
            report.gather(shard_report)?;
        }
    }
    let records = report.finish(&suite, &label, &cases)?;
    if args.gather.is_empty() {
        let shard = args.shard;
        println!("{label}: {} of {} cases (shard {}/{})", cases.len(), suite.cases.len(), shard.index, shard.count);
    } else {
        println!("{label}: {} cases gathered from {} reports", cases.len(), args.gather.len());
    }
    print_table(&records);
    let failed = records.iter().filter(|r| r.outcome != Outcome::Pass).count();
    println!("{}: {failed} of {} cases failed", if failed == 0 { "PASS" } else { "FAIL" }, records.len());
    println!("report: {}", folder.join(INDEX_FILE).display());
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}

/// The records as a table, in their order (worst first), each failure's reasons under it.
fn print_table(records: &[CaseRecord]) {
    println!(
        "  {:<6} {:<24} {:>11} {:>9} {:>9} {:>8} {:>8}",
        "", "case", "relMSE", "FLIP", "Z pass %", "mean z", "seconds"
    );
    for r in records {
        let (label, name, seconds) = (r.outcome.label(), &r.name, r.seconds);
        match &r.metrics {
            Some(m) => {
                let accepted = m.z_accepted_percent.map_or("-".into(), |p| format!("{p:.3}"));
                let mean_z = m.worst_mean_z.map_or("-".into(), |z| format!("{z:.2}"));
                println!(
                    "  {label:<6} {name:<24} {:>11.4e} {:>9.5} {accepted:>9} {mean_z:>8} {seconds:>8.1}",
                    m.relmse, m.mean_flip
                );
                if !r.problems.is_empty() {
                    println!("         {}", r.problems.join("; "));
                }
            }
            None => println!("  {label:<6} {name:<24} {}", r.problems.join("; ")),
        }
    }
}
