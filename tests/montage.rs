//! `tessera montage` and `tessera seams`: images on a labelled grid, the seam visibility of a
//! render, and clear errors for what they cannot do.

mod common;

use std::process::Command;

fn montage(args: &[&str], dir: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_tessera")).arg("montage").args(args).current_dir(dir).output().unwrap()
}

#[test]
fn montage_grids_images_and_refuses_bad_requests() {
    let dir = tempfile::tempdir().unwrap();
    let checker = common::repo().join("scenes/textures/checker.png");
    let brushed = common::repo().join("scenes/textures/brushed.png");
    let (a, b) = (checker.to_str().unwrap(), brushed.to_str().unwrap());
    let ok = montage(
        &[a, b, a, "--columns", "2", "--label", "one", "--label", "two", "--label", "three", "-o", "m.png"],
        dir.path(),
    );
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let m = tessera::image::read_bitmap(&dir.path().join("m.png"), tessera::image::ColorSpace::Srgb).unwrap();
    // Two columns of 256-pixel cells, two rows with captions: wider and taller than the images.
    assert!(m.width > 512 && m.width < 600 && m.height > 512 && m.height < 650, "{} x {}", m.width, m.height);
    let wrong_labels = montage(&[a, b, "--label", "one", "-o", "n.png"], dir.path());
    assert!(!wrong_labels.status.success());
    assert!(String::from_utf8_lossy(&wrong_labels.stderr).contains("--label"));
    let missing = montage(&[a, "nope.png", "-o", "n.png"], dir.path());
    assert!(String::from_utf8_lossy(&missing.stderr).contains("nope.png"));
    let bad_format = montage(&[a, "-o", "n.bmp"], dir.path());
    assert!(!bad_format.status.success());
    assert!(!dir.path().join("n.png").exists() && !dir.path().join("n.bmp").exists());
}

#[test]
fn seams_reads_the_render_aovs_and_names_what_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    // A render without AOVs: the error names the file and the channel it lacks.
    let plain = dir.path().join("plain.exr");
    let grey = vec![0.5f32; 16];
    let channels = ["R", "G", "B"].iter().map(|c| (c.to_string(), grey.clone())).collect();
    tessera::image::write_exr(&plain, 4, 4, channels).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_tessera")).arg("seams").arg(&plain).output().unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("plain.exr") && stderr.contains("uv.U"), "{stderr}");
}
