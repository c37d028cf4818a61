//! The deformation field of a UV-mapped mesh (paper 000 Sec. 4) against what it must be: on a
//! developable surface unrolled isometrically F is a rotation everywhere; a uniformly scaled
//! chart gives F = s R; degenerate triangles are reported and filled, never NaN.

mod common;

use glam::{Mat2, Vec2, Vec3};
use tessera::deform::{Orientation, Smoothing, deformation_maps};
use tessera::geometry::TriangleMesh;
use tessera::texture::tiling_blending::FieldAt;

/// Fold-over of the tiles' lookups of `maps`, read at the point, for centres 0.05 away.
fn point_fold(maps: &tessera::deform::DeformationMaps) -> tessera::deform::analysis::FoldOver {
    let charts = maps.chart_of_texels();
    tessera::deform::analysis::fold_over(&maps.f_map, &maps.coverage, &charts, 0.05, FieldAt::Point)
}

/// A strip of a cylinder of radius 0.5 about y (angles 0 to 1.6, height 0 to 0.8), unrolled
/// isometrically: u is the arc length along the polyline of chords (so that every flat triangle
/// keeps its shape exactly), times `scale`, and v the height times `scale`.
fn cylinder_strip(scale: f32) -> TriangleMesh {
    let (segments, rows) = (24, 8);
    let mut mesh = TriangleMesh::default();
    let mut uvs = Vec::new();
    let mut arc = 0.0;
    let point = |k: usize| {
        let a = 1.6 * k as f32 / segments as f32;
        Vec3::new(0.5 * a.cos(), 0.0, 0.5 * a.sin())
    };
    for k in 0..=segments {
        if k > 0 {
            arc += point(k).distance(point(k - 1));
        }
        for r in 0..=rows {
            let h = 0.8 * r as f32 / rows as f32;
            mesh.positions.push(point(k) + Vec3::Y * h);
            uvs.push((Vec2::new(arc, h) + Vec2::splat(0.05)) * scale);
        }
    }
    mesh.indices = common::grid_triangles(segments, rows);
    mesh.uvs = Some(uvs);
    mesh
}

fn each_f(map: &tessera::image::Bitmap) -> impl Iterator<Item = Mat2> + '_ {
    map.data.chunks_exact(4).map(|f| Mat2::from_cols(Vec2::new(f[0], f[2]), Vec2::new(f[1], f[3])))
}

#[test]
fn an_isometrically_unrolled_developable_surface_gives_rotations() {
    for orientation in [
        Orientation::Uv,
        Orientation::Fixed(Vec3::Y),
        Orientation::Parallels(Vec3::Y),
        Orientation::Geodesic(vec![Vec3::ZERO]),
    ] {
        for scale in [1.0f32, 0.5] {
            let maps =
                deformation_maps(&cylinder_strip(scale), &orientation, Smoothing::Vertices(1), 64, 0.25).unwrap();
            assert_eq!(maps.degenerate, 0);
            // F = R(theta) S with S = I / scale: F^T F = I / scale^2, det F = 1 / scale^2.
            for f in each_f(&maps.f_map) {
                let ftf = f.transpose() * f * (scale * scale);
                assert!(
                    (ftf - Mat2::IDENTITY).to_cols_array().iter().all(|e| e.abs() < 2e-3),
                    "{orientation:?}: F^T F = {ftf}"
                );
                assert!((f.determinant() * scale * scale - 1.0).abs() < 2e-3);
            }
        }
    }
    // With the UV orientation F is S alone: the identity here.
    let maps = deformation_maps(&cylinder_strip(1.0), &Orientation::Uv, Smoothing::Vertices(1), 64, 0.25).unwrap();
    assert!(each_f(&maps.f_map).all(|f| (f - Mat2::IDENTITY).to_cols_array().iter().all(|e| e.abs() < 2e-3)));
}

#[test]
fn fixed_orientation_lays_the_texture_along_the_direction() {
    // On the strip, the texture's x axis on the surface (J F^-1 e1, J = [dp/du dp/dv]) must run
    // along y, the cylinder's axis, which in this UV map is +v: so F^-1 e1 is along +v.
    let maps =
        deformation_maps(&cylinder_strip(1.0), &Orientation::Fixed(Vec3::Y), Smoothing::Vertices(1), 64, 0.25).unwrap();
    for f in each_f(&maps.f_map) {
        let along = (f.inverse() * Vec2::X).normalize();
        assert!(along.distance(Vec2::Y) < 1e-3, "{along}");
    }
}

#[test]
fn degenerate_triangles_are_counted_and_filled() {
    let mut mesh = cylinder_strip(1.0);
    let uvs = mesh.uvs.as_mut().unwrap();
    // Collapse the UVs of the first triangle and the 3D positions of another's.
    let [a, b, c] = mesh.indices[0];
    uvs[b as usize] = uvs[a as usize];
    uvs[c as usize] = uvs[a as usize];
    let [d, e, _] = mesh.indices[100];
    mesh.positions[e as usize] = mesh.positions[d as usize];
    let maps = deformation_maps(&mesh, &Orientation::Uv, Smoothing::Vertices(1), 64, 0.25).unwrap();
    assert!(maps.degenerate >= 2, "{}", maps.degenerate);
    assert!(maps.f_map.data.iter().all(|v| v.is_finite()));
    // A mesh without UVs, or with every triangle degenerate, is an error, not a panic.
    let mut no_uv = cylinder_strip(1.0);
    no_uv.uvs = None;
    assert!(deformation_maps(&no_uv, &Orientation::Uv, Smoothing::Vertices(1), 8, 0.25).is_err());
    let mut flat = cylinder_strip(1.0);
    flat.uvs.as_mut().unwrap().iter_mut().for_each(|u| *u = Vec2::splat(0.5));
    assert!(deformation_maps(&flat, &Orientation::Uv, Smoothing::Vertices(1), 8, 0.25).is_err());
}

#[test]
fn uv_area_outside_the_square_is_measured_and_a_mesh_mostly_outside_is_refused() {
    // The strip spans u from 0.05 to 0.05 plus its arc length (about 0.8), v from 0.05 to
    // 0.85: inside the square, as a map needs it. Its UV area is a rectangle.
    let mesh = cylinder_strip(1.0);
    let u_end = mesh.uvs.as_ref().unwrap().iter().map(|u| u.x).fold(0.0, f32::max) as f64;
    let shifted = |du: f32| {
        let mut mesh = mesh.clone();
        mesh.uvs.as_mut().unwrap().iter_mut().for_each(|u| u.x += du);
        deformation_maps(&mesh, &Orientation::Uv, Smoothing::Vertices(1), 64, 0.25)
    };
    assert_eq!(shifted(0.0).unwrap().outside_square, 0.0);
    // Moved right by 0.3: the part beyond u = 1 is reported.
    let partly = shifted(0.3).unwrap().outside_square;
    let expected = (u_end + 0.3 - 1.0) / (u_end - 0.05);
    assert!((partly - expected).abs() < 1e-4, "{partly} against {expected}");
    // Moved by a whole period (a UDIM tile): refused, saying why.
    let error = shifted(1.0).unwrap_err();
    assert!(error.contains("outside the unit square"), "{error}");
}

#[test]
fn cli_writes_the_f_map_and_pictures() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("strip.obj"), common::obj_text(&cylinder_strip(1.0))).unwrap();
    let out = dir.path().join("maps");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
        .arg("deform")
        .arg(dir.path().join("strip.obj"))
        .args(["--smoothing", "1", "--res", "32", "--orientation", "fixed:0,1,0", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let f = tessera::image::read_bitmap(&out.join("f_map.exr"), tessera::image::ColorSpace::Linear).unwrap();
    assert_eq!((f.width, f.height, f.channels), (32, 32, 4));
    assert!(["det_f.png", "orientation.png", "cut_bands.png"].iter().all(|p| out.join(p).exists()));
    // The chart map: one channel, the F map's size; the strip is one chart.
    let charts = tessera::image::read_bitmap_raw(&out.join("charts.exr"), tessera::image::ColorSpace::Linear).unwrap();
    assert_eq!((charts.width, charts.height, charts.channels), (32, 32, 1));
    assert!(charts.data.iter().all(|&c| c == 0.0));
    // One chart, no cuts: a cuts file without curves.
    let cuts = std::fs::read_to_string(out.join("cuts.json")).unwrap();
    assert!(tessera::texture::tiling_blending::cuts_from_json(&cuts).unwrap().is_empty(), "{cuts}");
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
        .arg("deform")
        .arg(dir.path().join("strip.obj"))
        .args(["--orientation", "sideways", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--orientation"));
}

#[test]
fn the_field_compensates_a_lat_long_sphere_distortion() {
    // The composite map surface -> exemplar (F J^+) of classical T&B on a lat-long sphere is
    // anisotropic and its scale varies with latitude; the deformation field (as the renderer
    // reads the F map) makes it nearly conformal and uniform. What is left is the difference
    // between a continuous field and the triangles' own Jacobians, which alternate between the
    // two triangles of each quad (their u edges lie on different parallels): a field matching
    // them would jump at every edge and fold the tiles' lookups, which it must not do here.
    let mesh = tessera::geometry::shapes::uv_sphere(64, 32);
    let maps = deformation_maps(&mesh, &Orientation::Uv, Smoothing::Vertices(1), 256, 0.25).unwrap();
    let f = tessera::texture::tiling_blending::Deformation::Map(tessera::texture::MipMap::new(maps.f_map.clone()));
    let classical = tessera::deform::distortion(&mesh, |_| Mat2::IDENTITY).unwrap();
    let deformed = tessera::deform::distortion(&mesh, |uv| f.at(uv)).unwrap();
    eprintln!("lat-long sphere: classical {classical:?}, deformed {deformed:?}");
    assert!(classical.mean_anisotropy > 1.3 && classical.std_log_area > 0.3, "{classical:?}");
    assert!(deformed.mean_anisotropy < 1.05, "{deformed:?}");
    assert!(deformed.std_log_area < 0.2 * classical.std_log_area, "{deformed:?}");
    let fold = point_fold(&maps);
    assert_eq!(fold.folded, 0.0, "{fold:?}");
}

#[test]
fn geodesic_orientation_runs_away_from_the_source() {
    // Source at the strip's start (arc length 0, mid-height): far from it the distance grows
    // along the arc, so the texture's x axis must point along +u where the strip is long.
    let strip = cylinder_strip(1.0);
    let source = Vec3::new(0.5, 0.4, 0.0);
    let maps =
        deformation_maps(&strip, &Orientation::Geodesic(vec![source]), Smoothing::Vertices(1), 64, 0.25).unwrap();
    let f = tessera::texture::tiling_blending::Deformation::Map(tessera::texture::MipMap::new(maps.f_map));
    // At the middle height, beyond the first third of the strip: away from the source is +u.
    for u in [0.5f32, 0.7, 0.85] {
        let along = (f.at(Vec2::new(u, 0.45)).inverse() * Vec2::X).normalize();
        assert!(along.dot(Vec2::X) > 0.97, "at u = {u}: texture x along {along}");
    }
}

#[test]
fn a_scene_reads_the_written_f_map_as_deform_computed_it() {
    // tessera deform's F map, referenced by a tiling_blending texture, orients the texture as
    // Eq. 7 says at the map's texel centres (where the renderer's bilinear lookup is exact).
    // Its entries are signed (here F = -I where theta = pi): nothing may clamp them on load.
    let strip = cylinder_strip(1.0);
    let maps = deformation_maps(&strip, &Orientation::Parallels(Vec3::Y), Smoothing::Vertices(1), 32, 0.25).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let f = &maps.f_map;
    let plane = |c: usize| f.data.iter().skip(c).step_by(4).copied().collect::<Vec<f32>>();
    let channels = ["R", "G", "B", "A"].iter().enumerate().map(|(c, n)| (n.to_string(), plane(c))).collect();
    tessera::image::write_exr(&dir.path().join("f_map.exr"), 32, 32, channels).unwrap();
    let mut png = Vec::new();
    image::GrayImage::from_pixel(4, 4, image::Luma([128]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    std::fs::write(dir.path().join("e.png"), png).unwrap();
    std::fs::write(
        dir.path().join("scene.toml"),
        "[camera]\nfov = 30\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n\
         [textures.e]\ntype = \"image\"\nfilename = \"e.png\"\n\
         [textures.tb]\ntype = \"tiling_blending\"\nexemplar = \"e\"\ndeformation = [{ type = \"map\", filename = \"f_map.exr\" }]\n",
    )
    .unwrap();
    let texture = tessera::scene::load_texture(&dir.path().join("scene.toml"), "tb", true).unwrap();
    for (i, j) in [(3, 4), (10, 20), (25, 7), (31, 31)] {
        let uv = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / 32.0;
        let f = maps.f_map.values(i, 31 - j);
        let expected = (Mat2::from_cols(Vec2::new(f[0], f[2]), Vec2::new(f[1], f[3])).inverse() * Vec2::X).normalize();
        let (direction, reversed) =
            texture.tangent_direction(uv, Some(false)).expect("a deformed texture has a direction");
        assert!(!reversed);
        assert!(direction.normalize().distance(expected) < 1e-4, "at {uv}: {direction} vs {expected}");
    }
}

#[test]
fn per_vertex_tangents_orient_like_the_field_they_sample() {
    // Tangents Y x p at the vertices sum, per triangle, to Y x (3 x centroid): the parallels
    // field around Y.
    let strip = cylinder_strip(1.0);
    let tangents: Vec<Vec3> = strip.positions.iter().map(|p| Vec3::Y.cross(*p)).collect();
    let given = deformation_maps(&strip, &Orientation::PerVertex(tangents), Smoothing::Vertices(1), 32, 0.25).unwrap();
    let parallels =
        deformation_maps(&strip, &Orientation::Parallels(Vec3::Y), Smoothing::Vertices(1), 32, 0.25).unwrap();
    for (a, b) in given.f_map.data.iter().zip(&parallels.f_map.data) {
        assert!((a - b).abs() < 1e-4, "{a} vs {b}");
    }
    // One tangent per vertex, finite.
    assert!(
        deformation_maps(&strip, &Orientation::PerVertex(vec![Vec3::X; 3]), Smoothing::Vertices(1), 8, 0.25).is_err()
    );
}

#[test]
fn cli_reads_gltf_meshes_and_their_tangents() {
    let dir = tempfile::tempdir().unwrap();
    let strip = cylinder_strip(1.0);
    std::fs::write(dir.path().join("strip.obj"), common::obj_text(&strip)).unwrap();
    let tangents = vec![Vec3::Y; strip.positions.len()];
    let (json, bin) = common::gltf_text(&strip, Some(&tangents), "strip.bin");
    std::fs::write(dir.path().join("strip.gltf"), json).unwrap();
    std::fs::write(dir.path().join("strip.bin"), bin).unwrap();
    let (json, bin) = common::gltf_text(&strip, None, "bare.bin");
    std::fs::write(dir.path().join("bare.gltf"), json).unwrap();
    std::fs::write(dir.path().join("bare.bin"), bin).unwrap();
    let deform = |mesh: &str, orientation: &str, out: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
            .arg("deform")
            .arg(dir.path().join(mesh))
            .args(["--smoothing", "1", "--res", "32", "--orientation", orientation, "-o"])
            .arg(dir.path().join(out))
            .output()
            .unwrap()
    };
    let read = |out: &str| {
        tessera::image::read_bitmap_raw(&dir.path().join(out).join("f_map.exr"), tessera::image::ColorSpace::Linear)
            .unwrap()
    };
    for (mesh, orientation, out) in [("strip.gltf", "tangents", "gltf"), ("strip.obj", "fixed:0,1,0", "obj")] {
        let run = deform(mesh, orientation, out);
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    }
    // The glTF's UVs (v flipped back on load) and tangents give the OBJ's fixed field.
    for (a, b) in read("gltf").data.iter().zip(&read("obj").data) {
        assert!((a - b).abs() < 1e-4, "{a} vs {b}");
    }
    let run = deform("bare.gltf", "tangents", "bare");
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("bare.gltf") && stderr.contains("TANGENT"), "{stderr}");
}

#[test]
fn orientation_error_is_zero_where_the_field_is_followed_and_measures_a_turn() {
    use tessera::deform::analysis::orientation_error;
    use tessera::texture::MipMap;
    use tessera::texture::tiling_blending::{Deformation, DeformationField};
    let mesh = cylinder_strip(1.0);
    for orientation in [Orientation::Fixed(Vec3::Y), Orientation::Parallels(Vec3::Y)] {
        let maps = deformation_maps(&mesh, &orientation, Smoothing::Vertices(1), 64, 0.25).unwrap();
        let field = DeformationField::new(vec![Deformation::Map(MipMap::new(maps.f_map.clone()))]);
        let followed = orientation_error(&mesh, &orientation, |uv, _| field.at(uv)).unwrap();
        assert!(followed.mean < 0.1 && followed.p95 < 0.2, "{orientation:?}: {followed:?}");
        // F R(30 degrees) turns the texture's axis by 30 degrees in UV, and the strip is
        // isometric: by 30 degrees on the surface.
        let turn = Mat2::from_angle(30f32.to_radians());
        let turned = orientation_error(&mesh, &orientation, |uv, _| field.at(uv) * turn).unwrap();
        assert!((turned.mean - 30.0).abs() < 0.2 && (turned.p95 - 30.0).abs() < 0.3, "{orientation:?}: {turned:?}");
    }
    assert!(orientation_error(&mesh, &Orientation::Uv, |_, _| Mat2::IDENTITY).is_none());
}

#[test]
fn triangles_own_fields_match_their_jacobians_but_tear_the_lookups() {
    // Paper 000 Fig. 4 c against d: unsmoothed, each triangle's F makes the composite map a
    // similarity on it (distortion 1 up to the map's texels), but F jumps at every edge, so the
    // tiles' lookups F(u)(u - c) fold there; smoothed per chart, they do not.
    let mesh = tessera::geometry::shapes::uv_sphere(64, 32);
    let analyse = |smoothing: Smoothing| {
        let maps = deformation_maps(&mesh, &Orientation::Uv, smoothing, 512, 0.05).unwrap();
        let f = tessera::texture::tiling_blending::Deformation::Map(tessera::texture::MipMap::new(maps.f_map.clone()));
        let distortion = tessera::deform::distortion(&mesh, |uv| f.at(uv)).unwrap();
        let fold = point_fold(&maps);
        (distortion, fold)
    };
    let (own, own_fold) = analyse(Smoothing::Triangles);
    let (smoothed, smoothed_fold) = analyse(Smoothing::Vertices(1));
    eprintln!("triangles: {own:?} {own_fold:?}; smoothed: {smoothed:?} {smoothed_fold:?}");
    assert!(own.mean_anisotropy < 1.02 && own.std_log_area < 0.02, "{own:?}");
    assert!(own_fold.folded + own_fold.stretched > 0.05, "{own_fold:?}");
    assert_eq!(smoothed_fold.folded, 0.0, "{smoothed_fold:?}");
}

/// A cube's six faces, `n` x `n` quads each, pushed onto the unit sphere, each face its own UV
/// square in a 3 x 2 layout; with `overlap`, the -x face (the +x face's mirror image) takes the
/// +x face's UV square with the same (a, b) parameters, so that the two share one island, the
/// -x face's copy mirrored.
fn cube_sphere(n: usize, overlap: bool) -> TriangleMesh {
    let faces = [
        (Vec3::new(1.0, -1.0, 1.0), Vec3::new(0.0, 0.0, -2.0), Vec3::new(0.0, 2.0, 0.0)),
        (Vec3::new(-1.0, -1.0, 1.0), Vec3::new(0.0, 0.0, -2.0), Vec3::new(0.0, 2.0, 0.0)),
        (Vec3::new(-1.0, 1.0, 1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -2.0)),
        (Vec3::new(-1.0, -1.0, -1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 2.0)),
        (Vec3::new(-1.0, -1.0, 1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0)),
        (Vec3::new(1.0, -1.0, -1.0), Vec3::new(-2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0)),
    ];
    let mut mesh = TriangleMesh::default();
    let mut uvs = Vec::new();
    for (f, (origin, du, dv)) in faces.iter().enumerate() {
        let slot = if overlap && f == 1 { 0 } else { f };
        let corner = Vec2::new((slot % 3) as f32 / 3.0 + 0.02, (slot / 3) as f32 / 2.0 + 0.1);
        let base = mesh.positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (a, b) = (i as f32 / n as f32, j as f32 / n as f32);
                mesh.positions.push((*origin + *du * a + *dv * b).normalize());
                // The -x face's (a, b) run against its outward winding: apart, its square is
                // flipped back; shared, it keeps the +x face's layout (mirrored).
                let a = if f == 1 && !overlap { 1.0 - a } else { a };
                uvs.push(corner + Vec2::new(a, b) * 0.28);
            }
        }
        for j in 0..n as u32 {
            for i in 0..n as u32 {
                let v00 = base + j * (n as u32 + 1) + i;
                let (v10, v01, v11) = (v00 + 1, v00 + n as u32 + 1, v00 + n as u32 + 2);
                if f == 1 {
                    mesh.indices.extend([[v00, v11, v10], [v00, v01, v11]]);
                } else {
                    mesh.indices.extend([[v00, v10, v11], [v00, v11, v01]]);
                }
            }
        }
    }
    mesh.uvs = Some(uvs);
    mesh
}

#[test]
fn overlapping_mirrored_islands_keep_one_field_and_the_other_half_mirrors_it() {
    // The +x and -x faces are mirror images sharing one UV square. The F map keeps the
    // unmirrored face's field; where the surface's UVs are mirrored the renderer mirrors it
    // (DeformationField::at_surface), so that the texture is not shown mirrored there: J F^-1
    // keeps the surface's orientation. Without that, the -x face shows it mirrored.
    use tessera::texture::MipMap;
    use tessera::texture::tiling_blending::{Deformation, DeformationField};
    let shown_mirrored = |mesh: &TriangleMesh, rule: bool| {
        let maps = deformation_maps(mesh, &Orientation::Fixed(Vec3::Y), Smoothing::Vertices(1), 256, 0.05).unwrap();
        let field = DeformationField::new(vec![Deformation::Map(MipMap::new(maps.f_map.clone()))]);
        let uvs = mesh.uvs.as_ref().unwrap();
        let (mut mirrored_area, mut total) = (0.0, 0.0);
        for idx in &mesh.indices {
            let x = idx.map(|i| mesh.positions[i as usize]);
            let u = idx.map(|i| uvs[i as usize]);
            let j = tessera::deform::deformation_gradient(x, u).unwrap();
            let uv_mirrored = (u[1] - u[0]).perp_dot(u[2] - u[0]) < 0.0;
            let centroid = (u[0] + u[1] + u[2]) / 3.0;
            let f = if rule { field.at_surface(centroid, Some(uv_mirrored)) } else { field.at(centroid) };
            let inverse = f.inverse();
            let axis = |k: Vec2| j.x_axis * k.x + j.y_axis * k.y;
            let (ex, ey) = (axis(inverse * Vec2::X), axis(inverse * Vec2::Y));
            let normal = (x[1] - x[0]).cross(x[2] - x[0]);
            let area = normal.length() / 2.0;
            total += area;
            if ex.cross(ey).dot(normal) < 0.0 {
                mirrored_area += area;
            }
        }
        (mirrored_area / total, maps.overlap().fraction())
    };
    let (apart, no_overlap) = shown_mirrored(&cube_sphere(8, false), true);
    let (shared, overlap) = shown_mirrored(&cube_sphere(8, true), true);
    let (without, _) = shown_mirrored(&cube_sphere(8, true), false);
    eprintln!("shown mirrored: apart {apart}, shared {shared}, shared without the rule {without}");
    assert_eq!(no_overlap, 0.0);
    assert!(overlap > 0.1, "{overlap}");
    assert_eq!((apart, shared), (0.0, 0.0));
    // The -x face: a sixth of the sphere.
    assert!((without - 1.0 / 6.0).abs() < 0.02, "{without}");
}

#[test]
fn deform_warns_about_cuts_that_no_band_closes() {
    // The lat-long icosphere's pole fans are UV singularities: cuts of their own, one edge each.
    let dir = tempfile::tempdir().unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
        .arg("deform")
        .arg(common::repo().join("scenes/meshes/smiley.obj"))
        .args(["--orientation", "parallels:0,0,1", "--tile-size", "0.1", "--res", "64", "-o"])
        .arg(dir.path().join("maps"))
        .output()
        .unwrap();
    assert!(run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("8 cut edges are UV singularities"), "{stderr}");
}

#[test]
fn packing_overlapping_charts_apart_gives_each_island_its_own_field() {
    // The cube sphere's -x face shares the +x face's UV square, mirrored. Parallels about z are
    // antisymmetric under that mirror, so the shared field turns the -x face's texture by 180
    // degrees. Packed apart, each face has its own field and follows the parallels.
    use tessera::deform::analysis::orientation_error;
    use tessera::deform::{pack_charts, uv_charts};
    use tessera::texture::MipMap;
    use tessera::texture::tiling_blending::{Deformation, DeformationField};
    let orientation = Orientation::Parallels(Vec3::Z);
    let measure = |mesh: &TriangleMesh| {
        let maps = deformation_maps(mesh, &orientation, Smoothing::Vertices(1), 256, 0.05).unwrap();
        let field = DeformationField::new(vec![Deformation::Map(MipMap::new(maps.f_map.clone()))]);
        let error = orientation_error(mesh, &orientation, |uv, mirrored| field.at_surface(uv, Some(mirrored))).unwrap();
        (error.mean, maps.overlap().fraction())
    };
    let stacked = cube_sphere(8, true);
    let (charts, count) = uv_charts(&stacked).unwrap();
    assert_eq!(count, 6);
    let packed = pack_charts(&stacked, &charts, 0.01).unwrap();
    let (before, overlap_before) = measure(&stacked);
    let (after, overlap_after) = measure(&packed.mesh);
    let (apart, _) = measure(&cube_sphere(8, false));
    eprintln!(
        "orientation error: stacked {before}, packed {after}, laid apart by hand {apart}; scale {}",
        packed.scale
    );
    assert!(overlap_before > 0.1 && overlap_after == 0.0, "{overlap_before} {overlap_after}");
    assert!(before > 20.0, "{before}");
    // (What is left is the parallels' singular points, on the +-z faces.)
    assert!(after < 3.0 && (after - apart).abs() < 0.1, "{after} against {apart}");
    // Only the UVs change, each chart's by one translation and the common scale: every UV edge
    // is the old one times the scale, orientation (mirrored or not) kept.
    assert_eq!((&packed.mesh.positions, &packed.mesh.indices), (&stacked.positions, &stacked.indices));
    let (old, new) = (stacked.uvs.as_ref().unwrap(), packed.mesh.uvs.as_ref().unwrap());
    for t in &stacked.indices {
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let expected = (old[b] - old[a]) * packed.scale;
            assert!((new[b] - new[a] - expected).length() < 1e-5, "{} against {expected}", new[b] - new[a]);
        }
    }
    assert!(new.iter().all(|uv| uv.cmpge(Vec2::splat(0.01 - 1e-6)).all() && uv.cmple(Vec2::splat(0.99 + 1e-6)).all()));
    // Charts that cannot fit at any scale: an error, not a panic.
    // (At 0.3 apart, two margins and two boxes of no size fill a row, two rows the square.)
    assert!(pack_charts(&stacked, &charts, 0.3).is_err());
}

#[test]
fn deform_repack_writes_the_mesh_it_packed_beside_the_maps() {
    let dir = tempfile::tempdir().unwrap();
    let stacked = cube_sphere(4, true);
    std::fs::write(dir.path().join("stacked.obj"), common::obj_text(&stacked)).unwrap();
    let deform = |mesh: &std::path::Path, out: &std::path::Path, repack: bool| {
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"));
        command.arg("deform").arg(mesh).args(["--res", "64", "--orientation", "parallels:0,0,1", "-o"]).arg(out);
        if repack {
            command.arg("--repack");
        }
        let run = command.output().unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        String::from_utf8_lossy(&run.stderr).into_owned()
    };
    let warned = deform(&dir.path().join("stacked.obj"), &dir.path().join("plain"), false);
    assert!(warned.contains("overlapping UV islands") && warned.contains("--repack"), "{warned}");
    assert!(!dir.path().join("plain/mesh.obj").exists());
    let told = deform(&dir.path().join("stacked.obj"), &dir.path().join("packed"), true);
    assert!(told.contains("mesh.obj"), "{told}");
    // The written mesh reads back with the same positions and triangles, and overlaps nowhere.
    let written = tessera::geometry::obj::load_obj(&dir.path().join("packed/mesh.obj")).unwrap();
    assert_eq!(written.indices.len(), stacked.indices.len());
    let corners =
        |m: &TriangleMesh| -> Vec<Vec3> { m.indices.iter().flatten().map(|&i| m.positions[i as usize]).collect() };
    assert!(corners(&written).iter().zip(corners(&stacked)).all(|(a, b)| a.distance(b) < 1e-6));
    let again = deform(&dir.path().join("packed/mesh.obj"), &dir.path().join("again"), false);
    assert!(!again.contains("overlapping"), "{again}");
}
