//! Regression suites (`tessera regress`): cases listed in a TOML file, each a scene to render
//! (or a ready-made test image) and a reference image to judge it against
//! ([`crate::image::compare::judge`]), split into shards for a scheduler's job array.
//!
//! A suite file:
//!
//! ```toml
//! [[case]]
//! name = "cornell_box"                      # letters, digits, '-', '_' and '.'
//! scene = "../scenes/golden/cornell_box.toml"   # or: test = "renders/cornell_box.exr"
//! spp = 122                                 # samples per pixel (the scene's if absent)
//! seed = 1                                  # sampler seed (the scene's if absent)
//! reference = "cornell_box.exr"
//! variance = "cornell_box.var.exr"          # per-sample variance: Mitsuba's Z-test
//! max_relmse = 0.01                         # and/or these limits
//! max_flip = 0.05
//! ```
//!
//! Paths are relative to the suite file's folder. A ready-made test image with a variance needs
//! its `spp`.

pub mod report;

use crate::error::{Error, Result};
use crate::image::Bitmap;
use crate::image::compare::{Criteria, Verdict, judge, read_reference, read_test_image};
use crate::scene::{SceneOverrides, load_scene};
use serde::Deserialize;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The suite file of a suite given as a folder.
pub const SUITE_FILE: &str = "suite.toml";

/// Largest suite file read, in bytes.
const MAX_SUITE_FILE_BYTES: u64 = 16 << 20;

/// A case as the file writes it.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CaseDesc {
    name: String,
    scene: Option<PathBuf>,
    test: Option<PathBuf>,
    spp: Option<u32>,
    seed: Option<u64>,
    reference: PathBuf,
    variance: Option<PathBuf>,
    max_relmse: Option<f64>,
    max_flip: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SuiteDesc {
    #[serde(rename = "case", default)]
    cases: Vec<CaseDesc>,
}

/// Where a case's test image comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum TestImage {
    /// A scene rendered with these samples per pixel and seed (the scene's where None).
    Render {
        /// The scene file.
        scene: PathBuf,
        /// Samples per pixel.
        spp: Option<u32>,
        /// Sampler seed.
        seed: Option<u64>,
    },
    /// An image made elsewhere (a GPU's, another renderer's), and its samples per pixel.
    File {
        /// The image.
        path: PathBuf,
        /// Its samples per pixel, for the Z-test.
        spp: Option<u32>,
    },
}

/// One case of a suite, its paths resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Its name (unique in the suite; a file name).
    pub name: String,
    /// The image under test.
    pub test: TestImage,
    /// The reference image.
    pub reference: PathBuf,
    /// The reference's per-sample variance (Mitsuba's Z-test).
    pub variance: Option<PathBuf>,
    /// Largest relMSE.
    pub max_relmse: Option<f64>,
    /// Largest mean FLIP.
    pub max_flip: Option<f64>,
}

/// A regression suite.
#[derive(Clone, Debug, PartialEq)]
pub struct Suite {
    /// The suite file.
    pub path: PathBuf,
    /// Its cases, in the file's order.
    pub cases: Vec<Case>,
}

impl Suite {
    /// Read and check a suite file (or a folder's `suite.toml`): every case named (uniquely),
    /// with a scene or a test image (not both), a reference and a criterion; errors name the
    /// file and the case.
    pub fn load(path: &Path) -> Result<Suite> {
        let file;
        let path = if path.is_dir() {
            file = path.join(SUITE_FILE);
            &file
        } else {
            path
        };
        let text = crate::files::read_text_bounded(path, MAX_SUITE_FILE_BYTES, "a suite file")?;
        let desc: SuiteDesc = toml::from_str(&text).map_err(|e| Error::scene(path, e.message().to_string()))?;
        if desc.cases.is_empty() {
            return Err(Error::scene(path, "the suite has no [[case]]"));
        }
        let base = path.parent().unwrap_or(Path::new("."));
        let mut names = HashSet::new();
        let cases = desc
            .cases
            .into_iter()
            .enumerate()
            .map(|(i, c)| {
                let fail = |msg: String| Error::scene(path, format!("case {} ('{}'): {msg}", i + 1, c.name));
                if !is_case_name(&c.name) {
                    return Err(fail(
                        "a name is 1 to 100 letters, digits, '-', '_' or '.', not starting with '.'".into(),
                    ));
                }
                if !names.insert(c.name.clone()) {
                    return Err(fail("another case has this name".into()));
                }
                for (key, limit) in [("max_relmse", c.max_relmse), ("max_flip", c.max_flip)] {
                    if limit.is_some_and(|l| !(l >= 0.0 && l.is_finite())) {
                        return Err(fail(format!("{key} must be a finite number >= 0")));
                    }
                }
                if c.spp == Some(0) || c.spp.is_some_and(|s| s > crate::limits::MAX_SPP) {
                    return Err(fail(format!("spp must be within 1..={}", crate::limits::MAX_SPP)));
                }
                let test = match (c.scene, c.test) {
                    (Some(scene), None) => TestImage::Render { scene: base.join(scene), spp: c.spp, seed: c.seed },
                    (None, Some(image)) if c.seed.is_none() => TestImage::File { path: base.join(image), spp: c.spp },
                    (None, Some(_)) => return Err(fail("a seed is for a scene to render, not a test image".into())),
                    _ => return Err(fail("give either `scene` (to render) or `test` (an image)".into())),
                };
                if c.variance.is_none() && c.max_relmse.is_none() && c.max_flip.is_none() {
                    return Err(fail("give a criterion: `variance` (the Z-test), `max_relmse` or `max_flip`".into()));
                }
                if c.variance.is_some() && matches!(test, TestImage::File { spp: None, .. }) {
                    return Err(fail("the Z-test of a test image needs its `spp`".into()));
                }
                Ok(Case {
                    name: c.name,
                    test,
                    reference: base.join(c.reference),
                    variance: c.variance.map(|v| base.join(v)),
                    max_relmse: c.max_relmse,
                    max_flip: c.max_flip,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Suite { path: path.to_path_buf(), cases })
    }

    /// The cases of `shard`, in the file's order.
    pub fn shard(&self, shard: Shard) -> Vec<&Case> {
        self.cases.iter().enumerate().filter(|(i, _)| shard.selects(*i)).map(|(_, c)| c).collect()
    }
}

/// Whether `name` may name a case: 1 to 100 letters, digits, '-', '_' or '.', not starting with
/// '.' (it names the case's folder in the report).
fn is_case_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 100
        && name.chars().all(|ch| ch.is_ascii_alphanumeric() || "-_.".contains(ch))
        && !name.starts_with('.')
}

/// Shard `index` of `count` (`--shard i/N`, 0 <= i < N, as a Slurm job array's or a Kubernetes
/// Indexed Job's index counts): case k of a suite belongs to shard k mod N, so that the shards
/// together run every case exactly once, and each the same cases whatever machine runs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    /// This shard, from 0.
    pub index: usize,
    /// How many shards.
    pub count: usize,
}

impl Shard {
    /// The one shard of an unsharded run.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Whether case `case` (its place in the suite, from 0) belongs to this shard.
    pub fn selects(&self, case: usize) -> bool {
        case % self.count == self.index
    }
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Self, String> {
        let (i, n) = text.split_once('/').ok_or_else(|| format!("'{text}' is not i/N"))?;
        let (index, count): (usize, usize) = (
            i.trim().parse().map_err(|_| format!("'{i}' is not a shard index"))?,
            n.trim().parse().map_err(|_| format!("'{n}' is not a shard count"))?,
        );
        if count == 0 || index >= count {
            return Err(format!("shard {index} of {count}: the index runs from 0 to N - 1"));
        }
        Ok(Shard { index, count })
    }
}

/// A case judged: its test image and reference (for the report) and the verdict.
pub struct Judged {
    /// The image under test (linear RGB).
    pub test: Bitmap,
    /// The reference (linear RGB).
    pub reference: Bitmap,
    /// The verdict, with its metrics and Z-test.
    pub verdict: Verdict,
}

/// How a case ended: judged, or why it could not be (a scene that does not load, a missing
/// reference: a failure of that case alone).
pub type CaseResult = std::result::Result<Judged, Error>;

/// Render or read a case's test image and judge it against its reference; `progress` is told
/// the samples done of the total, as the render goes.
pub fn run_case(case: &Case, progress: &(dyn Fn(u64, u64) + Sync)) -> CaseResult {
    let (test, invalid, spp) = match &case.test {
        TestImage::Render { scene, spp, seed } => {
            let scene = load_scene(scene, &SceneOverrides { spp: *spp, seed: *seed, ..Default::default() })?;
            let film = crate::integrator::render(&scene, None, &[], progress);
            (film.radiance(), film.invalid_sample_count() as usize, scene.settings.spp)
        }
        TestImage::File { path, spp } => {
            let (image, invalid) = read_test_image(path)?;
            (image, invalid, spp.unwrap_or(1))
        }
    };
    let reference = read_reference(&case.reference)?;
    let variance = case.variance.as_deref().map(read_reference).transpose()?;
    let criteria =
        Criteria { z_test: variance.as_ref().map(|v| (v, spp)), max_relmse: case.max_relmse, max_flip: case.max_flip };
    let verdict = judge(&test, invalid, &reference, &criteria)?;
    Ok(Judged { test, reference, verdict })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_run_every_case_exactly_once() {
        for count in 1..=7 {
            for cases in 0..20 {
                let mut runs = vec![0; cases];
                for index in 0..count {
                    let shard = Shard { index, count };
                    (0..cases).filter(|&k| shard.selects(k)).for_each(|k| runs[k] += 1);
                }
                assert!(runs.iter().all(|&r| r == 1), "{cases} cases in {count} shards: {runs:?}");
            }
        }
    }

    #[test]
    fn shards_parse_and_refuse_what_is_not_one() {
        assert_eq!("2/5".parse::<Shard>(), Ok(Shard { index: 2, count: 5 }));
        for bad in ["5/5", "1/0", "3", "-1/4", "a/b", "1/2/3"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
