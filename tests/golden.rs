//! Radiance goldens: every scene in `scenes/golden/` rendered by tessera must agree with its
//! Mitsuba 3 reference in `reference/` (made by `reference/generate.sh` from tessera's own
//! export of the scene), by Mitsuba's own test (`src/render/tests/test_renders.py`): a budget of
//! 2e6 samples per image, a per-pixel Z-test against the reference mean and per-sample variance
//! (Sidak-corrected at 0.01, at least 99.75% of pixels accepted), and here also the image mean
//! of each channel within 5 standard errors.
//!
//! On failure the test writes `target/golden/NAME/{actual,reference,variance,error,pvalue}.exr`
//! and prints their paths. A missing reference is a failure that says how to make it.

mod common;

use std::path::{Path, PathBuf};
use tessera::image::compare::{Criteria, absolute_difference, judge};
use tessera::image::{Bitmap, ColorSpace, read_bitmap, write_image};
use tessera::integrator::render;
use tessera::scene::{SceneOverrides, load_scene};

/// Samples per image (Mitsuba's render tests use the same).
const SAMPLE_BUDGET: u64 = 2_000_000;

fn names_in(dir: &Path, suffix: &str) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter_map(|f| f.strip_suffix(suffix).map(str::to_string))
        .collect();
    names.sort();
    names
}

fn golden_dir() -> PathBuf {
    common::repo().join("scenes/golden")
}

fn reference_dir() -> PathBuf {
    common::repo().join("reference")
}

#[test]
fn every_golden_scene_has_a_reference_and_every_reference_a_scene() {
    let scenes = names_in(&golden_dir(), ".toml");
    assert!(scenes.len() >= 6, "expected at least 6 golden scenes, found {scenes:?}");
    let references: Vec<String> =
        names_in(&reference_dir(), ".exr").into_iter().filter(|n| !n.ends_with(".var")).collect();
    for name in &scenes {
        for suffix in [".exr", ".var.exr", ".meta.toml"] {
            assert!(
                reference_dir().join(format!("{name}{suffix}")).exists(),
                "reference/{name}{suffix} is missing: run `bash reference/generate.sh {name}`"
            );
        }
    }
    for name in &references {
        assert!(scenes.contains(name), "reference/{name}.exr has no scene scenes/golden/{name}.toml");
    }
}

fn write_failure(name: &str, actual: &Bitmap, reference: &Bitmap, variance: &Bitmap, p_values: &Bitmap) -> PathBuf {
    let dir = common::repo().join("target/golden").join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let error = absolute_difference(actual, reference).unwrap();
    for (file, image) in
        [("actual", actual), ("reference", reference), ("variance", variance), ("error", &error), ("pvalue", p_values)]
    {
        write_image(&dir.join(format!("{file}.exr")), image, &[]).unwrap();
    }
    dir
}

#[test]
fn golden_scenes_match_mitsuba_references() {
    let mut failures = Vec::new();
    for name in names_in(&golden_dir(), ".toml") {
        let reference_path = reference_dir().join(format!("{name}.exr"));
        let variance_path = reference_dir().join(format!("{name}.var.exr"));
        if !reference_path.exists() || !variance_path.exists() {
            failures.push(format!("{name}: no reference; run `bash reference/generate.sh {name}`"));
            continue;
        }
        let reference = read_bitmap(&reference_path, ColorSpace::Linear).unwrap();
        let variance = read_bitmap(&variance_path, ColorSpace::Linear).unwrap();
        let pixels = (reference.width * reference.height) as u64;
        let spp = (SAMPLE_BUDGET / pixels).max(1) as u32;
        let scene = load_scene(
            &golden_dir().join(format!("{name}.toml")),
            &SceneOverrides { spp: Some(spp), ..Default::default() },
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let film = render(&scene, None, &[], &|_, _| {});
        let actual = film.radiance();
        let criteria = Criteria { z_test: Some((&variance, spp)), ..Default::default() };
        let verdict = judge(&actual, film.invalid_sample_count() as usize, &reference, &criteria).unwrap();
        let (metrics, z) = (&verdict.metrics, verdict.z.as_ref().expect("a Z-test was asked for"));
        println!(
            "{name:18} {spp} spp: {:.3}% of pixels pass, mean z {:?}, relMSE {:.3e}, FLIP {:.4}",
            100.0 * z.accepted_fraction,
            z.mean_z.map(|v| (v * 100.0).round() / 100.0),
            metrics.relmse,
            metrics.mean_flip
        );
        if !verdict.passes() {
            let dir = write_failure(&name, &actual, &reference, &variance, &z.p_values);
            failures.push(format!(
                "{name}: {}; images in {}/{{actual,reference,variance,error,pvalue}}.exr",
                verdict.failures.join("; "),
                dir.display()
            ));
        }
    }
    assert!(failures.is_empty(), "golden scenes differ from their Mitsuba references:\n{}", failures.join("\n"));
}
