//! The HTML report of `tessera regress` (src/regress/report.rs): one row and one section per case,
//! worst first; shards gathered into the same report as one run; a failed or interrupted run
//! leaves the previous report as it was; and, in a real browser (headless Chromium), every image
//! loads at every exposure, every column sorts, and the renders show in their colours.
//!
//! The browser part needs Chromium (`chromium`, `chromium-browser` or `google-chrome` on PATH, or
//! `TESSERA_BROWSER`); without one it is skipped with a message, unless
//! `TESSERA_REQUIRE_BROWSER=1` (as `.ci/run` sets, having installed Debian's `chromium`).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tessera() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tessera"))
}

/// The colour of the test images: linear (0.2, 0.05, 0), sRGB (124, 63, 0).
const COLOUR: [f32; 3] = [0.2, 0.05, 0.0];
/// Their bright corner, 8 x 8 pixels.
const BRIGHT: f32 = 4.0;

/// A 64 x 64 RGB EXR: `COLOUR` scaled by `gain`, with a bright 8 x 8 corner.
fn colour_exr(path: &Path, gain: f32) {
    let value = |c: usize, i: usize| if i % 64 < 8 && i / 64 < 8 { BRIGHT } else { COLOUR[c] * gain };
    let channels =
        ["R", "G", "B"].iter().enumerate().map(|(c, n)| (n.to_string(), (0..4096).map(|i| value(c, i)).collect()));
    tessera::image::write_exr(path, 64, 64, channels.collect()).unwrap();
}

/// A suite of five cases: two that pass (one by the Z-test), one deliberately broken (its test
/// image 40% too bright), one whose reference is missing, one that fails its FLIP limit.
fn suite(dir: &Path) -> PathBuf {
    colour_exr(&dir.join("reference.exr"), 1.0);
    colour_exr(&dir.join("same.exr"), 1.0);
    colour_exr(&dir.join("brighter.exr"), 1.4);
    colour_exr(&dir.join("variance.exr"), 0.05);
    let text = r#"
        [[case]]
        name = "same"
        test = "same.exr"
        reference = "reference.exr"
        max_relmse = 1e-6
        [[case]]
        name = "broken"
        test = "brighter.exr"
        reference = "reference.exr"
        max_relmse = 1e-3
        [[case]]
        name = "no-reference"
        test = "same.exr"
        reference = "missing.exr"
        max_flip = 0.1
        [[case]]
        name = "z-test"
        test = "same.exr"
        spp = 64
        reference = "reference.exr"
        variance = "variance.exr"
        [[case]]
        name = "flip"
        test = "brighter.exr"
        reference = "reference.exr"
        max_flip = 1e-4
    "#;
    std::fs::write(dir.join("suite.toml"), text).unwrap();
    dir.join("suite.toml")
}

fn regress(suite: &Path, args: &[&str]) -> Output {
    tessera().arg("regress").arg(suite).arg("-q").args(args).output().unwrap()
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The cases of a results file, in order, without their timings.
fn cases_without_seconds(results: &serde_json::Value) -> Vec<serde_json::Value> {
    let mut cases = results["cases"].as_array().unwrap().clone();
    cases.iter_mut().for_each(|c| c.as_object_mut().unwrap().remove("seconds").map(|_| ()).unwrap());
    cases
}

#[test]
fn the_report_has_every_case_worst_first_and_shards_gather_into_the_same_report() {
    let dir = tempfile::tempdir().unwrap();
    let suite = suite(dir.path());
    let full = dir.path().join("full");
    let out = regress(&suite, &["--report", full.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    let results = read_json(&full.join("results.json"));
    let order: Vec<(&str, &str)> = results["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| (c["name"].as_str().unwrap(), c["outcome"].as_str().unwrap()))
        .collect();
    // Worst first: the error, then the failures by relMSE (equal here: the same images), then the passes.
    assert_eq!(order[0], ("no-reference", "error"), "{order:?}");
    assert_eq!([order[1].1, order[2].1], ["fail", "fail"], "{order:?}");
    assert_eq!([order[3].1, order[4].1], ["pass", "pass"], "{order:?}");
    let html = std::fs::read_to_string(full.join("index.html")).unwrap();
    for (name, _) in &order {
        assert_eq!(html.matches(&format!("<a href=\"#case-{name}\">")).count(), 1, "{name}: one summary row");
        assert_eq!(html.matches(&format!("id=\"case-{name}\"")).count(), 1, "{name}: one section");
    }
    assert!(html.contains("missing.exr") && html.contains("relMSE"), "the error and the failure are on the page");
    // Every image the page links exists, each render at every exposure; the Z-test case has its
    // map of rejected pixels.
    for src in html.split("src=\"").skip(1).map(|s| &s[..s.find('"').unwrap()]) {
        assert!(full.join(src).is_file(), "{src}");
    }
    for stops in ["-4", "-1", "+1", "+4"] {
        assert!(full.join(format!("cases/broken/test.ev{stops}.png")).is_file(), "{stops}");
        assert!(full.join(format!("cases/same/reference.ev{stops}.png")).is_file(), "{stops}");
    }
    assert!(full.join("cases/z-test/rejected.png").is_file() && !full.join("cases/same/rejected.png").exists());
    assert!(full.join("cases/broken/montage.png").is_file());

    // Shards 0/2 and 1/2, gathered, make the same report.
    let shards: Vec<PathBuf> = (0..2).map(|i| dir.path().join(format!("shard-{i}"))).collect();
    for (i, shard) in shards.iter().enumerate() {
        let out = regress(&suite, &["--shard", &format!("{i}/2"), "--report", shard.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1), "both shards hold a failing case");
    }
    let gathered = dir.path().join("gathered");
    let out = regress(
        &suite,
        &["--gather", shards[0].to_str().unwrap(), shards[1].to_str().unwrap(), "--report", gathered.to_str().unwrap()],
    );
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stdout));
    assert_eq!(cases_without_seconds(&read_json(&gathered.join("results.json"))), cases_without_seconds(&results));
    for file in ["cases/broken/test.png", "cases/z-test/rejected.png", "cases/flip/montage.png"] {
        assert_eq!(std::fs::read(gathered.join(file)).unwrap(), std::fs::read(full.join(file)).unwrap(), "{file}");
    }

    // A gather that lacks a shard is an error naming the cases, and the good report stays.
    let before = std::fs::read(gathered.join("index.html")).unwrap();
    let out = regress(&suite, &["--gather", shards[0].to_str().unwrap(), "--report", gathered.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("no result for the cases broken, z-test"), "{stderr}");
    assert_eq!(std::fs::read(gathered.join("index.html")).unwrap(), before);
    // Gathering a shard twice is an error too.
    let twice = shards[0].to_str().unwrap();
    let out = regress(&suite, &["--gather", twice, twice, "--report", gathered.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("in two of the reports"));
    assert_eq!(std::fs::read(gathered.join("index.html")).unwrap(), before);
}

#[test]
fn an_interrupted_run_leaves_the_previous_report_in_place() {
    let dir = tempfile::tempdir().unwrap();
    colour_exr(&dir.path().join("reference.exr"), 1.0);
    let scene = common::repo().join("scenes/golden/cornell_box.toml");
    // A quick case, then a render long enough to be interrupted in.
    let text = format!(
        "[[case]]\nname = \"quick\"\ntest = \"reference.exr\"\nreference = \"reference.exr\"\nmax_flip = 0.1\n\
         [[case]]\nname = \"slow\"\nscene = {scene:?}\nspp = 100000\nreference = \"reference.exr\"\nmax_flip = 0.1\n"
    );
    std::fs::write(dir.path().join("suite.toml"), text).unwrap();
    let report = dir.path().join("report");
    std::fs::create_dir(&report).unwrap();
    std::fs::write(report.join("index.html"), "the previous report").unwrap();
    let mut child = tessera()
        .arg("regress")
        .arg(dir.path().join("suite.toml"))
        .args(["-q", "--report", report.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Wait until the quick case's images are staged, then kill the run (as a scheduler's time
    // limit or a Ctrl-C would) while it renders the slow one.
    let staged = |dir: &Path| {
        std::fs::read_dir(dir).unwrap().filter_map(|e| e.ok()).any(|e| {
            e.file_name().to_string_lossy().starts_with(".report.partial")
                && e.path().join("cases/quick/montage.png").is_file()
        })
    };
    let start = std::time::Instant::now();
    while !staged(dir.path()) {
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it could be interrupted");
        assert!(start.elapsed().as_secs() < 120, "the quick case was never staged");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(std::fs::read_to_string(report.join("index.html")).unwrap(), "the previous report");
    assert!(!report.join("cases").exists() && !report.join("results.json").exists());
}

/// Chromium, if this machine has it.
fn browser() -> Option<PathBuf> {
    if let Some(path) = std::env::var_os("TESSERA_BROWSER") {
        return Some(PathBuf::from(path));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| ["chromium", "chromium-browser", "google-chrome"].map(|name| dir.join(name)))
        .find(|candidate| candidate.is_file())
}

fn headless(browser: &Path, args: &[&str], url: &str) -> Output {
    Command::new(browser)
        .args(["--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--hide-scrollbars"])
        .args(args)
        .arg(url)
        .output()
        .unwrap()
}

#[test]
fn the_report_works_in_a_real_browser() {
    let Some(browser) = browser() else {
        assert!(
            std::env::var("TESSERA_REQUIRE_BROWSER").is_err(),
            "TESSERA_REQUIRE_BROWSER is set and no chromium was found on PATH"
        );
        eprintln!("no chromium on PATH: the browser test is skipped");
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let suite = suite(dir.path());
    let report = dir.path().join("report");
    regress(&suite, &["--report", report.to_str().unwrap()]);
    let url = format!("file://{}", report.join("index.html").display());
    // The page's own check (report.js, with #selftest): images loaded, rows, sections, sorting.
    let out = headless(&browser, &["--virtual-time-budget=10000", "--dump-dom"], &format!("{url}#selftest"));
    let dom = String::from_utf8_lossy(&out.stdout);
    let start = dom.find("<pre id=\"selftest\" data-done=\"yes\">").unwrap_or_else(|| panic!("no self-test:\n{dom}"));
    let text = &dom[start..];
    let json = &text[text.find('>').unwrap() + 1..text.find("</pre>").unwrap()];
    let check: serde_json::Value = serde_json::from_str(json).unwrap();
    // Per judged case: the wipe's two images, its own images, and the four renders (two in the
    // wipe, two beside it) at the 8 other exposures, as the self-test's probes.
    let results = read_json(&report.join("results.json"));
    let images: u64 = results["cases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["images"].as_array().unwrap().len() as u64)
        .filter(|&n| n > 0)
        .map(|n| n + 2 + 4 * 8)
        .sum();
    assert_eq!(check["images"], images, "{check}");
    assert_eq!(check["loaded"], images, "every image loads from the file system: {check}");
    assert_eq!([&check["rows"], &check["sections"], &check["cases"]], [5, 5, 5], "{check}");
    assert_eq!(check["sorts"], true, "every column sorts both ways: {check}");

    // A screenshot at exposure 0: the colour images show as sRGB (124, 63, 0).
    let shot = dir.path().join("shot.png");
    let arg = format!("--screenshot={}", shot.display());
    headless(&browser, &[&arg, "--window-size=1400,3000", "--force-device-scale-factor=1"], &url);
    let shot = image::open(&shot).unwrap().to_rgb8();
    let near = |p: &image::Rgb<u8>, q: [u8; 3]| p.0.iter().zip(q).all(|(a, b)| a.abs_diff(b) <= 1);
    let shown = shot.pixels().filter(|p| near(p, [124, 63, 0])).count();
    // Four judged cases, three views of the renders each, 2x zoom: far more than 4 x 3000.
    assert!(shown > 4 * 3000, "{shown} pixels show the colour");
}

#[test]
fn bad_report_folders_are_errors_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let suite = suite(dir.path());
    let file = dir.path().join("a_file");
    std::fs::write(&file, "not a folder").unwrap();
    let out = regress(&suite, &["--report", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("a_file: exists and is not a folder"));
    // A folder with no results.json, and a results.json that is not tessera's.
    let out = regress(&suite, &["--gather", dir.path().to_str().unwrap(), "--report", "unused"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("results.json"), "{out:?}");
    std::fs::write(dir.path().join("results.json"), r#"{"suite": "x", "cases": [{"name": "../x"}]}"#).unwrap();
    let out = regress(&suite, &["--gather", dir.path().to_str().unwrap(), "--report", "unused"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("not a tessera results file"), "{out:?}");
    assert_eq!(out.status.code(), Some(1));
    assert!(!Path::new("unused").exists());
}
