//! Regression suites (`tessera regress`, src/regress.rs): the shipped suite mirrors the golden
//! test, shards run every case exactly once, a failed or broken case does not stop the others,
//! and bad suite files are errors naming the file and the case.

mod common;

use std::process::Command;
use tessera::regress::{Shard, Suite, TestImage};

fn tessera() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tessera"))
}

#[test]
fn the_shipped_suite_is_the_golden_test() {
    let repo = common::repo();
    let suite = Suite::load(&repo.join("reference/suite.toml")).unwrap();
    let mut golden: Vec<String> = std::fs::read_dir(repo.join("scenes/golden"))
        .unwrap()
        .filter_map(|e| e.unwrap().file_name().to_str()?.strip_suffix(".toml").map(String::from))
        .collect();
    golden.sort();
    let mut names: Vec<String> = suite.cases.iter().map(|c| c.name.clone()).collect();
    names.sort();
    assert_eq!(names, golden, "reference/suite.toml lists every golden scene once");
    for case in &suite.cases {
        let TestImage::Render { scene, spp, .. } = &case.test else { panic!("{}: a scene to render", case.name) };
        assert!(scene.ends_with(format!("scenes/golden/{}.toml", case.name)), "{}", scene.display());
        // The golden test's budget: 2e6 samples per 128 x 128 image.
        assert_eq!(*spp, Some(122), "{}", case.name);
        assert!(case.reference.exists() && case.variance.as_ref().is_some_and(|v| v.exists()), "{}", case.name);
    }
    // Its shards together hold every case once.
    for count in 1..=4 {
        let mut seen: Vec<&str> =
            (0..count).flat_map(|index| suite.shard(Shard { index, count })).map(|c| c.name.as_str()).collect();
        seen.sort();
        assert_eq!(seen, names.iter().map(String::as_str).collect::<Vec<_>>(), "{count} shards");
    }
}

/// A 4 x 4 RGB EXR of one value.
fn exr(path: &std::path::Path, value: f32) {
    let channels = ["R", "G", "B"].iter().map(|c| (c.to_string(), vec![value; 16])).collect();
    tessera::image::write_exr(path, 4, 4, channels).unwrap();
}

#[test]
fn a_failed_or_broken_case_does_not_stop_the_others() {
    let dir = tempfile::tempdir().unwrap();
    for (name, value) in [("ref.exr", 0.5), ("same.exr", 0.5), ("off.exr", 0.9), ("var.exr", 0.01)] {
        exr(&dir.path().join(name), value);
    }
    let suite = r#"
        [[case]]
        name = "broken"
        test = "off.exr"
        reference = "ref.exr"
        max_relmse = 0.01
        [[case]]
        name = "missing"
        test = "same.exr"
        reference = "no_such.exr"
        max_flip = 0.1
        [[case]]
        name = "good"
        test = "same.exr"
        spp = 16
        reference = "ref.exr"
        variance = "var.exr"
    "#;
    std::fs::write(dir.path().join("suite.toml"), suite).unwrap();
    // A folder stands for its suite.toml.
    assert_eq!(Suite::load(dir.path()).unwrap().cases, Suite::load(&dir.path().join("suite.toml")).unwrap().cases);
    let report = dir.path().join("report");
    let out =
        tessera().arg("regress").arg(dir.path().join("suite.toml")).arg("-q").arg("--report").arg(&report).output();
    let out = out.unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}");
    // Every case is reported, the worst first: the one that could not run, then the failure.
    let order: Vec<usize> = ["ERROR  missing", "FAIL   broken", "PASS   good"]
        .iter()
        .map(|row| stdout.find(row).unwrap_or_else(|| panic!("no '{row}' in:\n{stdout}")))
        .collect();
    assert!(order.windows(2).all(|w| w[0] < w[1]), "{stdout}");
    assert!(stdout.contains("no_such.exr") && stdout.contains("relMSE"), "{stdout}");
    assert!(stdout.contains("FAIL: 2 of 3 cases failed"), "{stdout}");
    // Shard 2 of 3 holds the good case alone, and passes.
    let out = tessera()
        .arg("regress")
        .arg(dir.path().join("suite.toml"))
        .args(["-q", "--shard", "2/3", "--report"])
        .arg(&report)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stdout));
}

#[test]
fn bad_suite_files_name_the_case_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let case = |body: &str| format!("[[case]]\nname = \"c\"\nreference = \"r.exr\"\n{body}\n");
    let cases: &[(&str, &str)] = &[
        ("", "no [[case]]"),
        (&case("test = \"t.exr\""), "give a criterion"),
        (&case("max_flip = 0.1"), "either `scene`"),
        (&case("scene = \"s.toml\"\ntest = \"t.exr\"\nmax_flip = 0.1"), "either `scene`"),
        (&case("test = \"t.exr\"\nvariance = \"v.exr\""), "needs its `spp`"),
        (&case("test = \"t.exr\"\nseed = 3\nmax_flip = 0.1"), "a seed is for a scene"),
        (&case("test = \"t.exr\"\nmax_relmse = -1"), "max_relmse"),
        (&case("scene = \"s.toml\"\nspp = 0\nmax_flip = 0.1"), "spp"),
        (
            &format!("{}{}", case("test = \"t.exr\"\nmax_flip = 0.1"), case("test = \"t.exr\"\nmax_flip = 0.1")),
            "another case",
        ),
        (&case("test = \"t.exr\"\nmax_flip = 0.1\ncolour = 1"), "unknown field"),
        ("[[case]]\nname = \"../up\"\nreference = \"r.exr\"\ntest = \"t.exr\"\nmax_flip = 0.1\n", "a name is"),
    ];
    for (text, needle) in cases {
        let path = dir.path().join("suite.toml");
        std::fs::write(&path, text).unwrap();
        let msg = Suite::load(&path).unwrap_err().to_string();
        assert!(msg.contains("suite.toml") && msg.contains(needle), "{text:?}: {msg}");
        let out = tessera().arg("regress").arg(&path).output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{text:?}");
    }
    let out = tessera().args(["regress", "suite.toml", "--shard", "3/3"]).current_dir(dir.path()).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("index runs from 0"));
}
