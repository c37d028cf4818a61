//! The report of a regression run: `report/index.html` with, per case, the test image, the
//! reference, an error map and a FLIP map side by side (tone-mapped PNGs, an exposure control in
//! whole stops, a wipe that flips between test and reference), the metrics and the verdict, under
//! a sortable summary with the worst case first; and `results.json`, from which the reports of a
//! suite's shards are gathered into one.
//!
//! The page is one self-contained file plus the PNGs it links: no server, no network, no script
//! from elsewhere. The whole report is written to a staging folder and moved into place at the
//! end ([`StagedFolder`]), so an interrupted or failed run leaves the previous report as it was.

use super::{Case, CaseResult, Judged, Shard, Suite};
use crate::color::{luminance, srgb_to_linear};
use crate::error::{Error, Result};
use crate::files::StagedFolder;
use crate::image::compare::flip_map;
use crate::image::{Bitmap, montage, write_png};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// The report's page.
pub const INDEX_FILE: &str = "index.html";
/// The report's results, read back by [`Report::gather`].
pub const RESULTS_FILE: &str = "results.json";
/// The folder of the cases' images, one subfolder per case.
const CASES_FOLDER: &str = "cases";
/// Largest results file read back, in bytes.
const MAX_RESULTS_FILE_BYTES: u64 = 64 << 20;
/// The error map's range of relative squared error: log10 from -6 (black) to 0 (white).
const ERROR_MAP_DECADES: f32 = 6.0;
/// The exposures of the renders' PNGs, in stops: the page's exposure control switches between
/// them. (Exposing one PNG in the browser would be 8-bit: an SVG filter in linear light keeps 9
/// levels of a ramp's darkest 32nd, measured in Chromium; so each stop is tone-mapped here.)
const EXPOSURE_STOPS: std::ops::RangeInclusive<i32> = -4..=4;

/// How a case ended, worst first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// It could not be judged (a scene that does not load, a missing reference).
    Error,
    /// A criterion failed.
    Fail,
    /// Every criterion held.
    Pass,
}

impl Outcome {
    /// Its name on the page and in the table.
    pub fn label(self) -> &'static str {
        match self {
            Outcome::Error => "ERROR",
            Outcome::Fail => "FAIL",
            Outcome::Pass => "PASS",
        }
    }

    fn class(self) -> &'static str {
        match self {
            Outcome::Error => "error",
            Outcome::Fail => "fail",
            Outcome::Pass => "pass",
        }
    }
}

/// The images of a judged case, each a PNG in its folder.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CaseImage {
    /// The test image, tone-mapped (sRGB, clamped), one PNG per stop of [`EXPOSURE_STOPS`].
    Test,
    /// The reference, as the test image.
    Reference,
    /// Per pixel, the relMSE summand mean_c (t - r)^2 / (r^2 + 0.01), on a log scale.
    Error,
    /// Per pixel, LDR-FLIP in [0, 1].
    Flip,
    /// The pixels the Z-test rejects, red over the reference's luminance.
    Rejected,
}

impl CaseImage {
    /// Its file name's stem.
    fn stem(self) -> &'static str {
        match self {
            CaseImage::Test => "test",
            CaseImage::Reference => "reference",
            CaseImage::Error => "error",
            CaseImage::Flip => "flip",
            CaseImage::Rejected => "rejected",
        }
    }

    /// Its file at exposure `stops` (`test.png` at 0, `test.ev+1.png`, `test.ev-2.png`).
    fn file_at(self, stops: i32) -> String {
        match stops {
            0 => format!("{}.png", self.stem()),
            s => format!("{}.ev{s:+}.png", self.stem()),
        }
    }

    /// All its files: one per exposure for a render, one for a map.
    pub fn files(self) -> Vec<String> {
        match self.is_render() {
            true => EXPOSURE_STOPS.map(|s| self.file_at(s)).collect(),
            false => vec![self.file_at(0)],
        }
    }

    fn caption(self) -> &'static str {
        match self {
            CaseImage::Test => "test",
            CaseImage::Reference => "reference",
            CaseImage::Error => "relative squared error, log 1e-6 to 1",
            CaseImage::Flip => "FLIP, 0 to 1",
            CaseImage::Rejected => "Z-test: rejected pixels",
        }
    }

    /// Whether the exposure control applies (a render, not a map).
    fn is_render(self) -> bool {
        matches!(self, CaseImage::Test | CaseImage::Reference)
    }
}

/// The labelled strip of a case's images, made by `tessera montage`'s [`montage`].
const MONTAGE_FILE: &str = "montage.png";

/// What the report keeps of a case's metrics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordMetrics {
    /// relMSE.
    pub relmse: f64,
    /// Mean absolute error.
    pub mae: f64,
    /// Mean LDR-FLIP.
    pub mean_flip: f64,
    /// Percentage of pixels the Z-test accepts (where it ran).
    pub z_accepted_percent: Option<f64>,
    /// Largest |z| of a channel's image mean (where the Z-test ran).
    pub worst_mean_z: Option<f64>,
}

/// One case in the report: its outcome, why, its metrics and images.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseRecord {
    /// The case's name.
    pub name: String,
    /// Pass, fail or error.
    pub outcome: Outcome,
    /// The failed criteria, or the error.
    pub problems: Vec<String>,
    /// The metrics (absent when it could not be judged).
    pub metrics: Option<RecordMetrics>,
    /// Seconds to render (or read) and judge.
    pub seconds: f64,
    /// Width and height of its images (absent when it could not be judged).
    pub size: Option<(usize, usize)>,
    /// The images in its folder.
    pub images: Vec<CaseImage>,
}

impl CaseRecord {
    /// The order that puts the worst case first: errors, then failures, then passes, each by
    /// relMSE, largest first.
    pub fn worst_first(&self, other: &CaseRecord) -> std::cmp::Ordering {
        let relmse = |r: &CaseRecord| r.metrics.as_ref().map_or(f64::INFINITY, |m| m.relmse);
        self.outcome.cmp(&other.outcome).then(relmse(other).total_cmp(&relmse(self)))
    }
}

/// The contents of `results.json`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ResultsFile {
    /// The suite file, as given.
    suite: String,
    /// The cases, worst first.
    cases: Vec<CaseRecord>,
}

/// A report being written: cases are added as they are judged (their images go to the staging
/// folder at once), and [`Report::finish`] writes the page and moves everything into place.
pub struct Report {
    folder: StagedFolder,
    records: Vec<CaseRecord>,
}

impl Report {
    /// Begin a report in the folder `dir` (created if needed; its current contents stay until
    /// [`Report::finish`]).
    pub fn new(dir: &Path) -> Result<Report> {
        Ok(Report { folder: StagedFolder::new(dir)?, records: Vec::new() })
    }

    /// Add a case that was run, writing its images; returns its record.
    pub fn add(&mut self, case: &Case, result: &CaseResult, seconds: f64) -> Result<&CaseRecord> {
        let record = match result {
            Ok(judged) => {
                let folder = self.folder.path().join(CASES_FOLDER).join(&case.name);
                std::fs::create_dir_all(&folder).map_err(|e| Error::io(&folder, e))?;
                write_case_images(&folder, case, judged, seconds)?
            }
            Err(e) => CaseRecord {
                name: case.name.clone(),
                outcome: Outcome::Error,
                problems: vec![e.to_string()],
                metrics: None,
                seconds,
                size: None,
                images: Vec::new(),
            },
        };
        self.records.push(record);
        Ok(self.records.last().expect("just pushed"))
    }

    /// Add every case of another report (a shard's), copying its images; a case already in this
    /// report is an error.
    pub fn gather(&mut self, shard_report: &Path) -> Result<()> {
        let path = shard_report.join(RESULTS_FILE);
        let text = crate::files::read_text_bounded(&path, MAX_RESULTS_FILE_BYTES, "a report's results")?;
        let results: ResultsFile =
            serde_json::from_str(&text).map_err(|e| Error::scene(&path, format!("not a tessera results file: {e}")))?;
        for record in results.cases {
            if self.records.iter().any(|r| r.name == record.name) {
                return Err(Error::scene(&path, format!("case '{}' is in two of the reports gathered", record.name)));
            }
            if !super::is_case_name(&record.name) {
                return Err(Error::scene(&path, format!("case '{}' is not a case of a tessera report", record.name)));
            }
            let (from, to) = (
                shard_report.join(CASES_FOLDER).join(&record.name),
                self.folder.path().join(CASES_FOLDER).join(&record.name),
            );
            if !record.images.is_empty() {
                std::fs::create_dir_all(&to).map_err(|e| Error::io(&to, e))?;
                for file in record.images.iter().flat_map(|i| i.files()).chain([MONTAGE_FILE.to_string()]) {
                    std::fs::copy(from.join(&file), to.join(&file)).map_err(|e| Error::io(from.join(&file), e))?;
                }
            }
            self.records.push(record);
        }
        Ok(())
    }

    /// Check that the report holds exactly the cases `expected`, write `index.html` and
    /// `results.json` with the worst case first, and move the report into place. Returns the
    /// records, worst first.
    pub fn finish(mut self, suite: &Suite, suite_label: &str, expected: &[&Case]) -> Result<Vec<CaseRecord>> {
        let have: HashSet<&str> = self.records.iter().map(|r| r.name.as_str()).collect();
        let missing: Vec<&str> = expected.iter().map(|c| c.name.as_str()).filter(|n| !have.contains(n)).collect();
        if !missing.is_empty() {
            return Err(Error::scene(&suite.path, format!("no result for the cases {}", missing.join(", "))));
        }
        let wanted: HashSet<&str> = expected.iter().map(|c| c.name.as_str()).collect();
        if let Some(extra) = self.records.iter().find(|r| !wanted.contains(r.name.as_str())) {
            return Err(Error::scene(&suite.path, format!("the suite has no case '{}'", extra.name)));
        }
        // Worst first; equals in the suite's order, so that a gathered report orders as one run.
        let place = |r: &CaseRecord| expected.iter().position(|c| c.name == r.name);
        self.records.sort_by(|a, b| a.worst_first(b).then(place(a).cmp(&place(b))));
        let results = ResultsFile { suite: suite_label.to_string(), cases: self.records };
        let json = serde_json::to_string_pretty(&results).expect("records serialise");
        let staging = self.folder.path().to_path_buf();
        std::fs::write(staging.join(RESULTS_FILE), json).map_err(|e| Error::io(staging.join(RESULTS_FILE), e))?;
        let page = index_html(suite_label, expected.len() < suite.cases.len(), &results.cases);
        std::fs::write(staging.join(INDEX_FILE), page).map_err(|e| Error::io(staging.join(INDEX_FILE), e))?;
        self.folder.commit()?;
        Ok(results.cases)
    }
}

/// Write a judged case's images to `folder` and return its record.
fn write_case_images(folder: &Path, case: &Case, judged: &Judged, seconds: f64) -> Result<CaseRecord> {
    let Judged { test, reference, verdict } = judged;
    let exposed = |b: &Bitmap, stops: i32| Bitmap {
        width: b.width,
        height: b.height,
        channels: 3,
        data: (0..b.width * b.height)
            .flat_map(|i| b.data[i * b.channels..][..3].to_vec())
            .map(|v| v * (stops as f32).exp2())
            .collect(),
    };
    for stops in EXPOSURE_STOPS.filter(|&s| s != 0) {
        write_png(&folder.join(CaseImage::Test.file_at(stops)), &exposed(test, stops))?;
        write_png(&folder.join(CaseImage::Reference.file_at(stops)), &exposed(reference, stops))?;
    }
    let mut images = vec![
        (CaseImage::Test, exposed(test, 0)),
        (CaseImage::Reference, exposed(reference, 0)),
        (CaseImage::Error, error_map(test, reference)),
        (CaseImage::Flip, false_colour(&flip_map(test, reference)?.data, test.width, test.height)),
    ];
    if let Some(z) = &verdict.z {
        images.push((CaseImage::Rejected, rejected_map(&z.min_p_image(), z.alpha, &images[1].1)));
    }
    for (kind, image) in &images {
        write_png(&folder.join(kind.file_at(0)), image)?;
    }
    let cells: Vec<(Bitmap, String)> = images.iter().map(|(k, b)| (b.clone(), strip_caption(*k).to_string())).collect();
    let strip = montage(&cells, cells.len(), crate::limits::MAX_RENDER_PIXELS)
        .map_err(|msg| Error::param(format!("the montage of case '{}'", case.name), msg))?;
    write_png(&folder.join(MONTAGE_FILE), &strip)?;
    let m = &verdict.metrics;
    Ok(CaseRecord {
        name: case.name.clone(),
        outcome: if verdict.passes() { Outcome::Pass } else { Outcome::Fail },
        problems: verdict.failures.clone(),
        metrics: Some(RecordMetrics {
            relmse: m.relmse,
            mae: m.mae,
            mean_flip: m.mean_flip,
            z_accepted_percent: verdict.z.as_ref().map(|z| 100.0 * z.accepted_fraction),
            worst_mean_z: verdict.z.as_ref().map(|z| z.mean_z.iter().fold(0.0f64, |w, v| w.max(v.abs()))),
        }),
        seconds,
        size: Some((test.width, test.height)),
        images: images.iter().map(|(k, _)| *k).collect(),
    })
}

/// Short captions for the montage (its 8x8 font is wide).
fn strip_caption(kind: CaseImage) -> &'static str {
    match kind {
        CaseImage::Test => "test",
        CaseImage::Reference => "reference",
        CaseImage::Error => "rel. sq. error",
        CaseImage::Flip => "FLIP",
        CaseImage::Rejected => "Z rejected",
    }
}

/// The relMSE summand per pixel, mean over the channels, false-coloured on a log scale.
fn error_map(test: &Bitmap, reference: &Bitmap) -> Bitmap {
    let values: Vec<f32> = (0..test.width * test.height)
        .map(|i| {
            let (t, r) = (&test.data[i * test.channels..][..3], &reference.data[i * reference.channels..][..3]);
            let e = (0..3).map(|c| (t[c] - r[c]).powi(2) / (r[c] * r[c] + 0.01)).sum::<f32>() / 3.0;
            if e > 0.0 { (e.log10() / ERROR_MAP_DECADES + 1.0).clamp(0.0, 1.0) } else { 0.0 }
        })
        .collect();
    false_colour(&values, test.width, test.height)
}

/// Values in [0, 1] drawn with FLIP's magma colour map (as its own tool draws error maps).
fn false_colour(values: &[f32], width: usize, height: usize) -> Bitmap {
    let lut = nv_flip::magma_lut().to_vec();
    let data = values
        .iter()
        .flat_map(|v| {
            let k = (v.clamp(0.0, 1.0) * 255.0).round() as usize;
            lut[3 * k..3 * k + 3].iter().map(|&c| srgb_to_linear(c as f32 / 255.0)).collect::<Vec<_>>()
        })
        .collect();
    Bitmap { width, height, channels: 3, data }
}

/// The pixels whose smallest p-value is at or below `alpha`, red, over the (tone-mapped)
/// reference's luminance at a third.
fn rejected_map(min_p: &Bitmap, alpha: f64, reference: &Bitmap) -> Bitmap {
    let mut out = Bitmap::new(min_p.width, min_p.height, 3);
    for (i, px) in out.data.chunks_exact_mut(3).enumerate() {
        if (min_p.data[i] as f64) <= alpha {
            px.copy_from_slice(&[1.0, 0.0, 0.0]);
        } else {
            let r = &reference.data[3 * i..3 * i + 3];
            px.fill(luminance(crate::color::Rgb::new(r[0], r[1], r[2])).clamp(0.0, 1.0) / 3.0);
        }
    }
    out
}

/// `text` with the characters HTML gives a meaning escaped.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A number for the page (`-` when absent) and its sort value.
fn cell(value: Option<f64>, format: impl Fn(f64) -> String) -> String {
    match value {
        Some(v) => format!("<td data-value=\"{v:e}\">{}</td>", format(v)),
        None => "<td data-value=\"\">-</td>".to_string(),
    }
}

/// The page: header with the verdict and the controls, the summary, then one section per case,
/// all in the records' order (worst first).
fn index_html(suite_label: &str, partial: bool, records: &[CaseRecord]) -> String {
    let failed = records.iter().filter(|r| r.outcome != Outcome::Pass).count();
    let verdict = if failed == 0 { Outcome::Pass } else { Outcome::Fail };
    let small = records.iter().filter_map(|r| r.size).all(|(w, h)| w.max(h) <= 256);
    let mut html = String::new();
    html.push_str(&format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>tessera regress: {title}</title>\n<style>\n{css}</style>\n</head>\n\
         <body data-cases=\"{cases}\">\n<header>\n<h1>{title}</h1>\n\
         <p class=\"verdict {class}\">{label}: {failed} of {cases} cases failed{partial}</p>\n\
         <div class=\"controls\">\n\
         <label>exposure <input type=\"range\" id=\"exposure\" min=\"{min_ev}\" max=\"{max_ev}\" step=\"1\" value=\"0\"> \
         <output id=\"exposure-value\">+0 EV</output></label>\n\
         <label>zoom <select id=\"zoom\">{zoom}</select></label>\n\
         <span>click an image pair, or drag its slider, to flip between test and reference</span>\n\
         </div>\n</header>\n",
        title = escape(suite_label),
        css = include_str!("report.css"),
        cases = records.len(),
        class = verdict.class(),
        label = verdict.label(),
        min_ev = EXPOSURE_STOPS.start(),
        max_ev = EXPOSURE_STOPS.end(),
        partial = if partial { " (one shard of the suite)" } else { "" },
        zoom = [1, 2, 4]
            .iter()
            .map(|z| {
                let selected = if (*z == 2) == small { " selected" } else { "" };
                format!("<option value=\"{z}\"{selected}>{z}x</option>")
            })
            .collect::<String>(),
    ));
    html.push_str(
        "<table id=\"summary\">\n<thead><tr><th data-type=\"number\">#</th><th data-type=\"text\">case</th>\
         <th data-type=\"number\">result</th><th data-type=\"number\">relMSE</th><th data-type=\"number\">FLIP</th>\
         <th data-type=\"number\">Z-test pass %</th><th data-type=\"number\">worst mean z</th>\
         <th data-type=\"number\">seconds</th></tr></thead>\n<tbody>\n",
    );
    for (k, r) in records.iter().enumerate() {
        let m = r.metrics.as_ref();
        html.push_str(&format!(
            "<tr class=\"{class}\"><td data-value=\"{rank}\">{rank}</td><td data-value=\"{name}\">\
             <a href=\"#case-{name}\">{name}</a></td><td data-value=\"{outcome}\">{label}</td>{relmse}{flip}{z}{mean_z}{secs}</tr>\n",
            class = r.outcome.class(),
            rank = k + 1,
            name = escape(&r.name),
            outcome = r.outcome as u8,
            label = r.outcome.label(),
            relmse = cell(m.map(|m| m.relmse), |v| format!("{v:.3e}")),
            flip = cell(m.map(|m| m.mean_flip), |v| format!("{v:.4}")),
            z = cell(m.and_then(|m| m.z_accepted_percent), |v| format!("{v:.3}")),
            mean_z = cell(m.and_then(|m| m.worst_mean_z), |v| format!("{v:.2}")),
            secs = cell(Some(r.seconds), |v| format!("{v:.1}")),
        ));
    }
    html.push_str("</tbody>\n</table>\n");
    for r in records {
        html.push_str(&case_section(r));
    }
    html.push_str(&format!(
        "<pre id=\"selftest\"></pre>\n<script>\n{}</script>\n</body>\n</html>\n",
        include_str!("report.js")
    ));
    html
}

/// A case's section: verdict, problems, metrics, the wipe and the images side by side.
fn case_section(r: &CaseRecord) -> String {
    let name = escape(&r.name);
    let mut html = format!(
        "<section class=\"case {class}\" id=\"case-{name}\">\n<h2>{name} <span class=\"badge {class}\">{label}</span></h2>\n",
        class = r.outcome.class(),
        label = r.outcome.label(),
    );
    if !r.problems.is_empty() {
        let items: String = r.problems.iter().map(|p| format!("<li>{}</li>", escape(p))).collect();
        html.push_str(&format!("<ul class=\"problems\">{items}</ul>\n"));
    }
    if let Some(m) = &r.metrics {
        let optional = |v: Option<f64>, digits: usize| v.map_or("-".to_string(), |v| format!("{v:.digits$}"));
        html.push_str(&format!(
            "<table class=\"metrics\"><tr><th>relMSE</th><td>{:.4e}</td><th>MAE</th><td>{:.4e}</td>\
             <th>mean FLIP</th><td>{:.5}</td><th>Z-test pass %</th><td>{}</td><th>worst mean z</th><td>{}</td>\
             <th>seconds</th><td>{:.1}</td></tr></table>\n",
            m.relmse,
            m.mae,
            m.mean_flip,
            optional(m.z_accepted_percent, 3),
            optional(m.worst_mean_z, 2),
            r.seconds,
        ));
    }
    if let Some((w, h)) = r.size {
        let img = |image: CaseImage, class: &str| {
            // A render names its folder and stem, for the exposure control to pick its file.
            let stops = match image.is_render() {
                true => format!(" data-folder=\"{CASES_FOLDER}/{name}/\" data-stem=\"{}\"", image.stem()),
                false => String::new(),
            };
            format!(
                "<img class=\"px {class}\" src=\"{CASES_FOLDER}/{name}/{}\" alt=\"{name}: {}\" width=\"{w}\" height=\"{h}\"{stops}>",
                image.file_at(0),
                image.caption()
            )
        };
        html.push_str(&format!("<div class=\"images\" style=\"--w:{w};--h:{h}\">\n"));
        html.push_str(&format!(
            "<figure class=\"compare\"><div class=\"wipe\">{}{}</div><input type=\"range\" class=\"wipe-slider\" \
             min=\"0\" max=\"100\" value=\"50\" aria-label=\"wipe\"><figcaption class=\"which\">reference | test</figcaption></figure>\n",
            img(CaseImage::Reference, "reference"),
            img(CaseImage::Test, "test"),
        ));
        for image in &r.images {
            html.push_str(&format!(
                "<figure>{}<figcaption>{}</figcaption></figure>\n",
                img(*image, ""),
                image.caption()
            ));
        }
        html.push_str(&format!(
            "</div>\n<p><a href=\"{CASES_FOLDER}/{name}/{MONTAGE_FILE}\">the images as one labelled strip</a></p>\n"
        ));
    }
    html.push_str("</section>\n");
    html
}

/// The default report folder of a run: `report`, or for a shard `report/shard-i-of-N`, beside
/// which `--gather` puts the whole suite's report.
pub fn default_folder(shard: Shard) -> PathBuf {
    if shard == Shard::ALL {
        PathBuf::from("report")
    } else {
        PathBuf::from(format!("report/shard-{}-of-{}", shard.index, shard.count))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::color::linear_to_srgb;

    #[test]
    fn the_error_map_is_black_where_equal_and_white_at_relative_error_one() {
        let a = Bitmap { width: 2, height: 1, channels: 3, data: vec![0.5, 0.5, 0.5, 0.0, 0.0, 0.0] };
        let b = Bitmap { width: 2, height: 1, channels: 3, data: vec![0.5, 0.5, 0.5, 1.0, 1.0, 1.0] };
        let map = error_map(&a, &b);
        let lut = nv_flip::magma_lut().to_vec();
        let encoded = |v: f32| (linear_to_srgb(v) * 255.0).round() as u8;
        assert_eq!(map.data[..3].iter().map(|&v| encoded(v)).collect::<Vec<_>>(), lut[..3]);
        // (0 - 1)^2 / (1 + 0.01) = 0.99: the top of the scale, less 0.0007 of it.
        assert_eq!(map.data[3..].iter().map(|&v| encoded(v)).collect::<Vec<_>>(), lut[765..768]);
    }

    #[test]
    fn text_is_escaped() {
        assert_eq!(escape("<a href=\"x\">&'"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
    }
}
