//! Scale-out of one render: four `--crop` renders merged by `tessera merge` equal the full
//! render bit for bit, every channel (radiance, AOVs, variance).

mod common;

use std::process::Command;
use tessera::image::read_exr_image;

#[test]
fn four_crops_merged_equal_the_full_render_bit_for_bit() {
    let dir = common::scene_dir(
        "[render]\nwidth = 24\nheight = 18\nspp = 4\nseed = 7\n\
         [camera]\nfov = 40\neye = [0, 1, 4]\ntarget = [0, 0, 0]\n\
         [environment]\ntype = \"constant\"\nradiance = 0.5\n\
         [materials.m]\ntype = \"diffuse\"\nreflectance = [0.7, 0.4, 0.2]\n\
         [[shapes]]\ntype = \"uv_sphere\"\nmaterial = \"m\"\n\
         [[shapes]]\ntype = \"rectangle\"\nemission = 2\ntransform = [{ translate = [0, 3, 0] }]\n",
        &[],
    );
    let tessera = || Command::new(env!("CARGO_BIN_EXE_tessera"));
    let render = |crop: Option<&str>, out: &str| {
        let mut cmd = tessera();
        cmd.arg("render").arg(dir.path().join("scene.toml")).args(["--aov", "albedo,uv", "--variance", "-q", "-o"]);
        cmd.arg(dir.path().join(out));
        if let Some(c) = crop {
            cmd.args(["--crop", c]);
        }
        let status = cmd.output().unwrap();
        assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
        dir.path().join(out)
    };
    let full = render(None, "full.exr");
    // Uneven pieces: a top strip, and the bottom split in three.
    let crops: Vec<_> = ["0,0,24,5", "0,5,7,18", "7,5,20,18", "20,5,24,18"]
        .iter()
        .enumerate()
        .map(|(k, c)| render(Some(c), &format!("crop{k}.exr")))
        .collect();
    let merged = dir.path().join("merged.exr");
    let status = tessera().arg("merge").args(&crops).arg("-o").arg(&merged).output().unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let (a, b) = (read_exr_image(&full).unwrap(), read_exr_image(&merged).unwrap());
    assert_eq!((a.width, a.height), (24, 18));
    assert!(a.channels.len() >= 3 + 3 + 2 + 3);
    for ((name_a, va), (name_b, vb)) in a.channels.iter().zip(&b.channels) {
        assert_eq!(name_a, name_b);
        let same = va.iter().zip(vb).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "channel {name_a} differs");
    }
    // Three crops leave a gap: an error naming it, and no output.
    let gap = dir.path().join("gap.exr");
    let status = tessera().arg("merge").args(&crops[..3]).arg("-o").arg(&gap).output().unwrap();
    assert_eq!(status.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&status.stderr).contains("in no crop"));
    assert!(!gap.exists());
}
