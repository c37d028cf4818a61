//! Every scene in `scenes/` and its folders of figures (not `scenes/golden/`, which
//! `tests/golden.rs` checks) loads without warnings and renders a finite, lit image; the README
//! names each of them.

mod common;

use tessera::integrator::render;
use tessera::scene::{SceneOverrides, load_scene};

fn shipped_scenes() -> Vec<std::path::PathBuf> {
    let toml_files = |dir: &std::path::Path| {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect::<Vec<_>>()
    };
    let root = common::repo().join("scenes");
    let mut scenes = toml_files(&root);
    for entry in std::fs::read_dir(&root).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() && path.file_name().is_some_and(|n| n != "golden") {
            scenes.extend(toml_files(&path));
        }
    }
    scenes.sort();
    scenes
}

#[test]
fn shipped_scenes_render_out_of_the_box() {
    let scenes = shipped_scenes();
    assert!(scenes.len() >= 4, "expected the four shipped scenes, found {scenes:?}");
    let readme = std::fs::read_to_string(common::repo().join("README.md")).unwrap();
    for path in scenes {
        let name = path.strip_prefix(common::repo().join("scenes")).unwrap().to_string_lossy().into_owned();
        let overrides = SceneOverrides { width: Some(24), height: Some(16), spp: Some(4), ..Default::default() };
        let scene = load_scene(&path, &overrides).unwrap_or_else(|e| panic!("{e}"));
        assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
        let film = render(&scene, None, &[], &|_, _| {});
        assert_eq!(film.invalid_sample_count(), 0, "{name}");
        let means = film.radiance().channel_means();
        assert!(means.iter().all(|m| m.is_finite() && *m > 0.01 && *m < 50.0), "{name}: channel means {means:?}");
        assert!(readme.contains(&name), "README.md does not mention {name}");
    }
}
