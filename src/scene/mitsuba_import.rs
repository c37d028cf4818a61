//! `tessera import-mitsuba`: the part of Mitsuba 3's XML scene format that tessera renders as
//! Mitsuba does, translated into a scene file, and a list of everything that was not.
//!
//! Translated: `<default>` parameters (`$name`); the `path` integrator; `perspective`,
//! `thinlens` and `orthographic` sensors with their film and sampler; `obj`, `ply`, `rectangle`,
//! `cube`, `sphere` and `serialized` shapes; transforms; the BSDFs tessera has
//! (`diffuse`, `conductor`, `roughconductor`, `dielectric`, `roughdielectric`, `roughplastic`,
//! wrapped in `twosided` and `normalmap`), `bitmap` textures and `<ref>`s to them; `area`,
//! `point`, `spot`, `directional`, `constant` and `envmap` emitters. Each item that is not
//! translated exactly is named in [`MitsubaImport::untranslated`], with what was done instead.
//!
//! Conventions converted: Mitsuba's sensor looks down its local +z with x to the left (tessera's
//! down -z, x right), its field of view spans x by default, its near clip defaults to 0.01, and
//! its bitmaps' v runs down (a `to_uv` of scale s and translation t becomes tessera's scale s and
//! offset (t_x, 1 - s_y - t_y), the inverse of `export-mitsuba`'s).

use super::load::mitsuba_look_at;
use crate::error::{Error, Result};
use crate::files::read_text_bounded;
use crate::geometry::Sphere;
use crate::limits;
use glam::{Mat4, Vec3, Vec4};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// A translated scene and what could not be translated exactly.
#[derive(Debug)]
pub struct MitsubaImport {
    /// The scene file's contents.
    pub scene: Table,
    /// One line per item not translated exactly: what it was and what tessera does instead.
    pub untranslated: Vec<String>,
}

impl MitsubaImport {
    /// The scene as TOML text, with a header naming its source.
    pub fn to_toml(&self, source: &Path) -> String {
        let mut text = format!("# Imported by tessera import-mitsuba from {}\n", source.display());
        for line in &self.untranslated {
            text += &format!("# not translated exactly: {line}\n");
        }
        text + "\n" + &toml::to_string(&self.scene).expect("a table of plain values serialises")
    }
}

/// Translate the Mitsuba 3 scene `xml`; file names in the result are relative to `out_dir`
/// (where the scene file will be written) when they can be, absolute otherwise.
pub fn import_mitsuba(xml: &Path, out_dir: &Path) -> Result<MitsubaImport> {
    let text = read_text_bounded(xml, limits::MAX_SCENE_FILE_BYTES, "a Mitsuba scene")?;
    let parse = |text| roxmltree::Document::parse(text).map_err(|e| Error::scene(xml, format!("malformed XML: {e}")));
    let text = with_defaults(&parse(&text)?, &text);
    let doc = parse(&text)?;
    let root = doc.root_element();
    if root.tag_name().name() != "scene" {
        return Err(Error::scene(xml, format!("the root element is <{}>, not <scene>", root.tag_name().name())));
    }
    let base = xml.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut importer = Importer {
        base,
        out_dir: if out_dir.as_os_str().is_empty() { PathBuf::from(".") } else { out_dir.to_path_buf() },
        ids: HashMap::new(),
        scene: Table::new(),
        materials: Table::new(),
        textures: Table::new(),
        shapes: Vec::new(),
        lights: Vec::new(),
        untranslated: Vec::new(),
    };
    importer.scene_children(root).map_err(|msg| Error::scene(xml, msg))?;
    let mut scene = importer.scene;
    for (key, items) in [("materials", importer.materials), ("textures", importer.textures)] {
        if !items.is_empty() {
            scene.insert(key.into(), Value::Table(items));
        }
    }
    for (key, items) in [("lights", importer.lights), ("shapes", importer.shapes)] {
        if !items.is_empty() {
            scene.insert(key.into(), Value::Array(items.into_iter().map(Value::Table).collect()));
        }
    }
    if !scene.contains_key("camera") {
        return Err(Error::scene(xml, "the scene has no <sensor>: tessera needs a camera"));
    }
    Ok(MitsubaImport { scene, untranslated: importer.untranslated })
}

/// `text` with the `<default name="..." value="..."/>` parameters of its root substituted for
/// `$name`, as Mitsuba substitutes them in every attribute (`type` and `id` included); the
/// first definition of a name counts, and longer names are replaced first, so that `$spp` does
/// not take the start of `$spp_preview`.
fn with_defaults(doc: &roxmltree::Document, text: &str) -> String {
    let mut defaults: Vec<(&str, &str)> = Vec::new();
    for node in doc.root_element().children().filter(|c| c.has_tag_name("default")) {
        if let (Some(name), Some(value)) = (node.attribute("name"), node.attribute("value"))
            && !defaults.iter().any(|(n, _)| *n == name)
        {
            defaults.push((name, value));
        }
    }
    defaults.sort_by_key(|(name, _)| std::cmp::Reverse(name.len()));
    defaults.iter().fold(text.to_string(), |text, (name, value)| text.replace(&format!("${name}"), value))
}

type Node<'a, 'i> = roxmltree::Node<'a, 'i>;
type Parsed<T> = std::result::Result<T, String>;

struct Importer {
    base: PathBuf,
    out_dir: PathBuf,
    /// Elements with an `id`, for `<ref>`: their translated name (a material or texture).
    ids: HashMap<String, String>,
    scene: Table,
    materials: Table,
    textures: Table,
    shapes: Vec<Table>,
    lights: Vec<Table>,
    untranslated: Vec<String>,
}

/// Where an element is in the file, for messages.
fn at(node: Node) -> String {
    let kind = node.attribute("type").map_or(String::new(), |t| format!(" type=\"{t}\""));
    let id = node.attribute("id").map_or(String::new(), |i| format!(" id=\"{i}\""));
    format!("<{}{kind}{id}>", node.tag_name().name())
}

fn numbers(text: &str, what: &str) -> Parsed<Vec<f32>> {
    text.split([',', ' ', '\t', '\n'])
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<f32>().map_err(|_| format!("{what}: '{s}' is not a number")))
        .collect()
}

/// A number as TOML writes it: the shortest decimal that reads back as the same f32 (0.3, not
/// 0.30000001192092896).
fn num(v: f32) -> Value {
    Value::Float(v.to_string().parse().expect("an f32's decimal is a valid f64"))
}

fn floats(values: &[f32]) -> Value {
    Value::Array(values.iter().map(|v| num(*v)).collect())
}

impl Importer {
    /// An attribute's value (`$name` defaults are substituted in the whole file before).
    fn attr(&self, node: Node, name: &str) -> Option<String> {
        node.attribute(name).map(str::to_string)
    }

    fn skip(&mut self, what: String) {
        self.untranslated.push(what);
    }

    /// The child property element called `name`.
    fn property<'a, 'i>(&self, node: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
        node.children().find(|c| c.is_element() && c.attribute("name") == Some(name))
    }

    fn float(&self, node: Node, name: &str) -> Parsed<Option<f32>> {
        let Some(p) = self.property(node, name) else { return Ok(None) };
        let value = self.attr(p, "value").ok_or_else(|| format!("{}: {name} has no value", at(node)))?;
        value.trim().parse::<f32>().map(Some).map_err(|_| format!("{}: {name} = '{value}' is not a number", at(node)))
    }

    fn integer(&self, node: Node, name: &str) -> Parsed<Option<i64>> {
        self.string(node, name)
            .map(|v| v.trim().parse::<i64>().map_err(|_| format!("{}: {name} = '{v}' is not an integer", at(node))))
            .transpose()
    }

    fn string(&self, node: Node, name: &str) -> Option<String> {
        self.property(node, name).and_then(|p| self.attr(p, "value"))
    }

    fn boolean(&self, node: Node, name: &str) -> bool {
        self.string(node, name).is_some_and(|v| v == "true")
    }

    /// A point or vector: `value="x, y, z"` or x, y, z attributes (missing ones 0).
    fn vector_of(&self, p: Node) -> Parsed<Vec3> {
        if let Some(v) = self.attr(p, "value") {
            let n = numbers(&v, &at(p))?;
            return match n[..] {
                [x, y, z] => Ok(Vec3::new(x, y, z)),
                [s] => Ok(Vec3::splat(s)),
                _ => Err(format!("{}: expected three numbers, got '{v}'", at(p))),
            };
        }
        let c = |k: &str| {
            self.attr(p, k).map_or(Ok(0.0), |v| v.trim().parse::<f32>().map_err(|_| format!("{}: {k} = '{v}'", at(p))))
        };
        Ok(Vec3::new(c("x")?, c("y")?, c("z")?))
    }

    fn vector(&self, node: Node, name: &str) -> Parsed<Option<Vec3>> {
        self.property(node, name).map(|p| self.vector_of(p)).transpose()
    }

    /// A colour: `rgb` (three numbers or one), `spectrum` or `float` (one number); a texture
    /// (inline `bitmap` or `<ref>`) as the texture's name. None if absent.
    fn color(&mut self, node: Node, name: &str) -> Parsed<Option<Value>> {
        let Some(p) = self.property(node, name) else { return Ok(None) };
        match p.tag_name().name() {
            "rgb" | "spectrum" | "float" => {
                let v = self.attr(p, "value").ok_or_else(|| format!("{}: {name} has no value", at(node)))?;
                let n = numbers(&v, &format!("{}: {name}", at(node)))
                    .map_err(|e| format!("{e} (spectra given by wavelength are not translated)"))?;
                Ok(Some(match n[..] {
                    [s] => num(s),
                    [r, g, b] => floats(&[r, g, b]),
                    _ => return Err(format!("{}: {name} = '{v}': expected 1 or 3 numbers", at(node))),
                }))
            }
            "texture" => self.texture(p).map(|t| t.map(Value::String)),
            "ref" => {
                let id = self.attr(p, "id").unwrap_or_default();
                match self.ids.get(&id) {
                    Some(name) => Ok(Some(Value::String(name.clone()))),
                    None => Err(format!("{}: <ref id=\"{id}\"> names nothing defined before it", at(node))),
                }
            }
            other => Err(format!("{}: {name} is a <{other}>", at(node))),
        }
    }

    /// A file name as the output scene refers to it.
    fn file(&self, name: &str) -> String {
        let path = self.base.join(name);
        let absolute = std::path::absolute(&path).unwrap_or(path);
        let out = std::path::absolute(&self.out_dir).unwrap_or(self.out_dir.clone());
        match absolute.strip_prefix(&out) {
            Ok(relative) => relative.to_string_lossy().replace('\\', "/"),
            Err(_) => absolute.to_string_lossy().into_owned(),
        }
    }

    /// A `<texture>`: a `bitmap` becomes an image texture; its name, or None (with a note)
    /// for other kinds.
    fn texture(&mut self, node: Node) -> Parsed<Option<String>> {
        let kind = node.attribute("type").unwrap_or_default();
        let mut texture = Table::new();
        match kind {
            "bitmap" => {
                let filename = self.string(node, "filename").ok_or_else(|| format!("{}: no filename", at(node)))?;
                texture.insert("type".into(), "image".into());
                texture.insert("filename".into(), self.file(&filename).into());
                if self.boolean(node, "raw") {
                    texture.insert("colorspace".into(), "linear".into());
                }
                if let Some(filter) = self.string(node, "filter_type").filter(|f| f != "bilinear") {
                    self.skip(format!("{}: filter_type '{filter}' read bilinearly", at(node)));
                }
                if let Some(wrap) = self.string(node, "wrap_mode").filter(|w| w != "repeat") {
                    self.skip(format!("{}: wrap_mode '{wrap}' read as repeat", at(node)));
                }
            }
            "checkerboard" => {
                texture.insert("type".into(), "checkerboard".into());
                for key in ["color0", "color1"] {
                    match self.color(node, key)? {
                        Some(Value::String(_)) => {
                            self.skip(format!("{}: a textured {key} is not translated (its default instead)", at(node)))
                        }
                        Some(c) => {
                            texture.insert(key.into(), c);
                        }
                        None => {}
                    }
                }
            }
            _ => {
                self.skip(format!(
                    "{}: only bitmap and checkerboard textures are translated (the parameter keeps its default)",
                    at(node)
                ));
                return Ok(None);
            }
        }
        if let Some(t) = node.children().find(|c| c.has_tag_name("transform") && c.attribute("name") == Some("to_uv")) {
            let m = self.transform(t)?;
            let affine = m.x_axis.y == 0.0 && m.y_axis.x == 0.0;
            if !affine {
                self.skip(format!("{}: a rotated or sheared to_uv is not translated", at(node)));
            } else {
                let (s, o) = ([m.x_axis.x, m.y_axis.y], [m.w_axis.x, 1.0 - m.y_axis.y - m.w_axis.y]);
                texture.insert("scale".into(), floats(&s));
                texture.insert("offset".into(), floats(&o));
            }
        }
        let name = match node.attribute("id") {
            Some(id) => id.to_string(),
            None => format!("texture{}", self.textures.len()),
        };
        self.textures.insert(name.clone(), Value::Table(texture));
        if let Some(id) = node.attribute("id") {
            self.ids.insert(id.to_string(), name.clone());
        }
        Ok(Some(name))
    }

    /// A `<transform>`'s matrix: each step applied after the ones before it.
    fn transform(&self, node: Node) -> Parsed<Mat4> {
        let mut m = Mat4::IDENTITY;
        for step in node.children().filter(|c| c.is_element()) {
            let here = at(step);
            let op = match step.tag_name().name() {
                "translate" => Mat4::from_translation(self.vector_of(step)?),
                "scale" => {
                    let mut s = self.vector_of(step)?;
                    if self.attr(step, "value").is_none() {
                        // Missing axes of <scale x=".."/> are 1, not 0.
                        let given = |k: &str| step.attribute(k).is_some();
                        s = Vec3::new(
                            if given("x") { s.x } else { 1.0 },
                            if given("y") { s.y } else { 1.0 },
                            if given("z") { s.z } else { 1.0 },
                        );
                    }
                    Mat4::from_scale(s)
                }
                "rotate" => {
                    let axis =
                        self.vector_of(step)?.try_normalize().ok_or_else(|| format!("{here}: no rotation axis"))?;
                    let angle = self.attr(step, "angle").unwrap_or_default();
                    let angle: f32 = angle.trim().parse().map_err(|_| format!("{here}: angle '{angle}'"))?;
                    Mat4::from_axis_angle(axis, angle.to_radians())
                }
                "matrix" => {
                    let v = self.attr(step, "value").unwrap_or_default();
                    match numbers(&v, &here)?[..] {
                        ref n if n.len() == 16 => Mat4::from_cols_array(n.try_into().expect("16")).transpose(),
                        ref n if n.len() == 9 => Mat4::from_cols(
                            Vec4::new(n[0], n[3], n[6], 0.0),
                            Vec4::new(n[1], n[4], n[7], 0.0),
                            Vec4::new(n[2], n[5], n[8], 0.0),
                            Vec4::W,
                        ),
                        _ => return Err(format!("{here}: a matrix needs 16 (or 9) numbers")),
                    }
                }
                "lookat" => {
                    let p = |k: &str| -> Parsed<Vec3> {
                        let v = self.attr(step, k).ok_or_else(|| format!("{here}: no {k}"))?;
                        match numbers(&v, &here)?[..] {
                            [x, y, z] => Ok(Vec3::new(x, y, z)),
                            _ => Err(format!("{here}: {k} needs three numbers")),
                        }
                    };
                    let up = if step.attribute("up").is_some() { p("up")? } else { Vec3::Y };
                    mitsuba_look_at(p("origin")?, p("target")?, up)
                        .ok_or_else(|| format!("{here}: origin, target and up do not define a view"))?
                }
                other => return Err(format!("{here}: unknown transform step <{other}>")),
            };
            m = op * m;
        }
        if !m.is_finite() {
            return Err(format!("{}: the transform is not finite", at(node)));
        }
        Ok(m)
    }

    fn to_world(&self, node: Node) -> Parsed<Option<Mat4>> {
        node.children()
            .find(|c| c.has_tag_name("transform") && c.attribute("name") == Some("to_world"))
            .map(|t| self.transform(t))
            .transpose()
    }

    fn scene_children(&mut self, root: Node) -> Parsed<()> {
        for node in root.children().filter(|c| c.is_element()) {
            match node.tag_name().name() {
                "default" => {}
                "integrator" => self.integrator(node)?,
                "sensor" => self.sensor(node)?,
                "bsdf" => {
                    self.bsdf(node)?;
                }
                "texture" => {
                    self.texture(node)?;
                }
                "shape" => self.shape(node)?,
                "emitter" => self.emitter(node)?,
                other => self.skip(format!("{}: <{other}> is not translated", at(node))),
            }
        }
        Ok(())
    }

    fn render_table(&mut self) -> &mut Table {
        self.scene.entry("render").or_insert_with(|| Value::Table(Table::new())).as_table_mut().expect("a table")
    }

    fn integrator(&mut self, node: Node) -> Parsed<()> {
        let kind = node.attribute("type").unwrap_or_default();
        match kind {
            "path" => {}
            "volpath" | "prb" => self.skip(format!("{}: rendered as tessera's path tracer (no media)", at(node))),
            _ => {
                self.skip(format!("{}: rendered as tessera's path tracer", at(node)));
            }
        }
        let (max_depth, rr_depth) = (self.integer(node, "max_depth")?, self.integer(node, "rr_depth")?);
        let render = self.render_table();
        render.insert("max_depth".into(), Value::Integer(max_depth.unwrap_or(-1)));
        if let Some(rr) = rr_depth {
            render.insert("rr_depth".into(), Value::Integer(rr));
        }
        Ok(())
    }

    fn sensor(&mut self, node: Node) -> Parsed<()> {
        let kind = node.attribute("type").unwrap_or_default();
        let mut camera = Table::new();
        let film = node.children().find(|c| c.has_tag_name("film"));
        let int = |this: &Self, n: Option<Node>, name: &str, default: i64| -> Parsed<i64> {
            match n.and_then(|n| this.string(n, name)) {
                Some(v) => v.trim().parse().map_err(|_| format!("{}: {name} = '{v}'", at(node))),
                None => Ok(default),
            }
        };
        let (width, height) = (int(self, film, "width", 768)?, int(self, film, "height", 576)?);
        // Mitsuba's film filters with a Gaussian of stddev 0.5 unless told otherwise.
        let rfilter = film.and_then(|f| f.children().find(|c| c.has_tag_name("rfilter")));
        let mut filter = Table::new();
        match rfilter.map_or("gaussian", |r| r.attribute("type").unwrap_or_default()) {
            "box" => {}
            "gaussian" => {
                filter.insert("type".into(), "gaussian".into());
                let stddev = rfilter.map(|r| self.float(r, "stddev")).transpose()?.flatten();
                filter.insert("stddev".into(), num(stddev.unwrap_or(0.5)));
            }
            "tent" => {
                filter.insert("type".into(), "tent".into());
                let radius = rfilter.map(|r| self.float(r, "radius")).transpose()?.flatten();
                filter.insert("radius".into(), num(radius.unwrap_or(1.0)));
            }
            other => self.skip(format!(
                "{}: reconstruction filter '{other}' rendered with a box filter (each pixel the mean over its square)",
                at(rfilter.expect("a named filter"))
            )),
        }
        let sampler = node.children().find(|c| c.has_tag_name("sampler"));
        let spp = int(self, sampler, "sample_count", 4)?;
        let seed = int(self, sampler, "seed", 0)?;
        if let Some(s) = sampler.and_then(|s| s.attribute("type")).filter(|t| *t != "independent") {
            self.skip(format!("<sampler type=\"{s}\">: tessera's independent sampler is used"));
        }
        let render = self.render_table();
        for (k, v) in [("width", width), ("height", height), ("spp", spp), ("seed", seed)] {
            render.insert(k.into(), Value::Integer(v));
        }
        if !filter.is_empty() {
            render.insert("filter".into(), Value::Table(filter));
        }
        let to_world = self.to_world(node)?.unwrap_or(Mat4::IDENTITY);
        // Mitsuba's camera looks down +z with x left; tessera's down -z with x right.
        let mut m = to_world * Mat4::from_scale(Vec3::new(-1.0, 1.0, -1.0));
        match kind {
            "perspective" | "thinlens" => {
                let (fov, axis) = self.field_of_view(node, width as f32 / height as f32)?;
                camera.insert("fov".into(), num(fov));
                camera.insert("fov_axis".into(), axis.into());
                if kind == "thinlens" {
                    for key in ["aperture_radius", "focus_distance"] {
                        let v = self.float(node, key)?.ok_or_else(|| format!("{}: {key} is required", at(node)))?;
                        camera.insert(key.into(), num(v));
                    }
                }
            }
            "orthographic" => {
                // The film spans x in [-1, 1] before to_world: its x scale is the half-width.
                let half = m.x_axis.truncate().length();
                m.x_axis /= half;
                m.y_axis /= m.y_axis.truncate().length();
                camera.insert("projection".into(), "orthographic".into());
                camera.insert("extent".into(), num(2.0 * half));
                camera.insert("fov_axis".into(), "x".into());
            }
            other => return Err(format!("{}: sensor type '{other}' is not translated", at(node))),
        }
        let near = self.float(node, "near_clip")?.unwrap_or(0.01);
        camera.insert("near_clip".into(), num(near));
        camera.insert("matrix".into(), floats(&m.transpose().to_cols_array()));
        self.scene.insert("camera".into(), Value::Table(camera));
        Ok(())
    }

    /// The field of view in degrees and the axis tessera gives it along: Mitsuba's `fov` along
    /// `fov_axis` (x, y, diagonal, smaller, larger), or a `focal_length` on 35 mm film (default
    /// 50 mm, along the diagonal).
    fn field_of_view(&self, node: Node, aspect: f32) -> Parsed<(f32, &'static str)> {
        let (fov, axis) = match self.float(node, "fov")? {
            Some(fov) => (fov, self.string(node, "fov_axis").unwrap_or_else(|| "x".into())),
            None => {
                let f = self.string(node, "focal_length").unwrap_or_else(|| "50mm".into());
                let mm: f32 =
                    f.trim_end_matches("mm").trim().parse().map_err(|_| format!("{}: focal_length '{f}'", at(node)))?;
                ((36f32.hypot(24.0) / (2.0 * mm)).atan().to_degrees() * 2.0, "diagonal".to_string())
            }
        };
        let half = (fov.to_radians() * 0.5).tan();
        let x_from = |along: f32| 2.0 * (half / along).atan().to_degrees();
        Ok(match axis.as_str() {
            "x" => (fov, "x"),
            "y" => (fov, "y"),
            "diagonal" => (x_from(1.0f32.hypot(1.0 / aspect)), "x"),
            "smaller" => (fov, if aspect >= 1.0 { "y" } else { "x" }),
            "larger" => (fov, if aspect >= 1.0 { "x" } else { "y" }),
            other => return Err(format!("{}: fov_axis '{other}'", at(node))),
        })
    }

    /// A `<bsdf>`: added to the materials; its name, or None (a note) for kinds tessera lacks.
    fn bsdf(&mut self, node: Node) -> Parsed<Option<String>> {
        let mut two_sided = false;
        let mut normal_map = None;
        let mut inner = node;
        loop {
            match inner.attribute("type") {
                Some("twosided") => two_sided = true,
                Some("normalmap") => {
                    normal_map = match self.property(inner, "normalmap") {
                        Some(t) if t.has_tag_name("texture") => self.texture(t)?,
                        _ => None,
                    }
                }
                _ => break,
            }
            let Some(child) = inner.children().find(|c| c.has_tag_name("bsdf")) else {
                return Err(format!("{}: holds no <bsdf>", at(inner)));
            };
            inner = child;
        }
        let kind = inner.attribute("type").unwrap_or_default().to_string();
        let mut m = Table::new();
        let put = |m: &mut Table, key: &str, value: Option<Value>| {
            if let Some(v) = value {
                m.insert(key.into(), v);
            }
        };
        let float = |this: &Self, key: &str| -> Parsed<Option<Value>> { Ok(this.float(inner, key)?.map(num)) };
        let ior = |this: &Self, key: &str| -> Parsed<Option<Value>> {
            Ok(this.string(inner, key).map(|v| match v.trim().parse::<f64>() {
                Ok(x) => Value::Float(x),
                Err(_) => Value::String(v),
            }))
        };
        // Mitsuba's rough BSDFs default to Beckmann; tessera's microfacets are GGX.
        if kind.starts_with("rough") {
            match self.string(inner, "distribution") {
                Some(d) if d == "ggx" => {}
                Some(d) => self.skip(format!("{}: distribution '{d}' rendered as GGX", at(inner))),
                None => self.skip(format!(
                    "{}: no distribution given: Mitsuba's default, Beckmann, is rendered as GGX",
                    at(inner)
                )),
            }
        }
        match kind.as_str() {
            "diffuse" => {
                m.insert("type".into(), "diffuse".into());
                let r = self.color(inner, "reflectance")?;
                put(&mut m, "reflectance", r);
            }
            "conductor" | "roughconductor" => {
                m.insert("type".into(), "conductor".into());
                if kind == "roughconductor" {
                    self.roughness(inner, &mut m)?;
                }
                if let Some(name) = self.string(inner, "material") {
                    if crate::material::named_conductor(&name).is_some() {
                        m.insert("material".into(), name.into());
                    } else {
                        self.skip(format!(
                            "{}: conductor '{name}' is not in tessera's table (Mitsuba's but AlSb): rendered as a perfect mirror; \
                             give its eta and k",
                            at(inner)
                        ));
                    }
                }
                for key in ["eta", "k"] {
                    let v = self.color(inner, key)?;
                    put(&mut m, key, v);
                }
                if m.contains_key("eta") != m.contains_key("k") {
                    return Err(format!("{}: give both eta and k", at(inner)));
                }
                let s = self.color(inner, "specular_reflectance")?;
                put(&mut m, "specular_reflectance", s);
            }
            "dielectric" | "roughdielectric" | "thindielectric" => {
                if kind == "thindielectric" {
                    self.skip(format!("{}: rendered as a solid dielectric", at(inner)));
                }
                m.insert("type".into(), "dielectric".into());
                if kind == "roughdielectric" {
                    self.roughness(inner, &mut m)?;
                }
                put(&mut m, "int_ior", ior(self, "int_ior")?);
                put(&mut m, "ext_ior", ior(self, "ext_ior")?);
                for key in ["specular_reflectance", "specular_transmittance"] {
                    let v = self.color(inner, key)?;
                    put(&mut m, key, v);
                }
            }
            "roughplastic" | "plastic" => {
                m.insert("type".into(), "plastic".into());
                let alpha = if kind == "plastic" {
                    self.skip(format!("{}: smooth plastic rendered as rough plastic with alpha 0.001", at(inner)));
                    Some(Value::Float(0.001))
                } else {
                    float(self, "alpha")?
                };
                put(&mut m, "alpha", alpha);
                if self.boolean(inner, "nonlinear") {
                    self.skip(format!("{}: nonlinear = true rendered as false", at(inner)));
                }
                put(&mut m, "int_ior", ior(self, "int_ior")?);
                put(&mut m, "ext_ior", ior(self, "ext_ior")?);
                for key in ["diffuse_reflectance", "specular_reflectance"] {
                    let v = self.color(inner, key)?;
                    put(&mut m, key, v);
                }
            }
            other => {
                self.skip(format!("{}: BSDF '{other}' rendered as diffuse 0.5", at(node)));
                m.insert("type".into(), "diffuse".into());
            }
        }
        if two_sided {
            if kind.contains("dielectric") {
                self.skip(format!("{}: a two-sided dielectric is rendered one-sided (already two-sided)", at(node)));
            } else {
                m.insert("two_sided".into(), Value::Boolean(true));
            }
        }
        put(&mut m, "normal_map", normal_map.map(Value::String));
        let name = node.attribute("id").map_or_else(|| format!("bsdf{}", self.materials.len()), str::to_string);
        self.materials.insert(name.clone(), Value::Table(m));
        if let Some(id) = node.attribute("id") {
            self.ids.insert(id.to_string(), name.clone());
        }
        Ok(Some(name))
    }

    /// A rough BSDF's `alpha`, or `alpha_u` and `alpha_v` (Mitsuba's default alpha is 0.1).
    fn roughness(&self, node: Node, m: &mut Table) -> Parsed<()> {
        let value = |key: &str| -> Parsed<Option<Value>> { Ok(self.float(node, key)?.map(num)) };
        match (value("alpha_u")?, value("alpha_v")?) {
            (Some(u), Some(v)) => {
                m.insert("alpha_u".into(), u);
                m.insert("alpha_v".into(), v);
            }
            (None, None) => {
                m.insert("alpha".into(), value("alpha")?.unwrap_or(Value::Float(0.1)));
            }
            _ => return Err(format!("{}: give both alpha_u and alpha_v", at(node))),
        }
        Ok(())
    }

    fn shape(&mut self, node: Node) -> Parsed<()> {
        let kind = node.attribute("type").unwrap_or_default();
        let mut shape = Table::new();
        let mut m = self.to_world(node)?.unwrap_or(Mat4::IDENTITY);
        match kind {
            "obj" | "ply" | "serialized" => {
                shape.insert("type".into(), kind.into());
                let f = self.string(node, "filename").ok_or_else(|| format!("{}: no filename", at(node)))?;
                shape.insert("filename".into(), self.file(&f).into());
                if let Some(index) = self.integer(node, "shape_index")?.filter(|_| kind == "serialized") {
                    shape.insert("shape_index".into(), Value::Integer(index));
                }
                if self.boolean(node, "face_normals") {
                    self.skip(format!("{}: face_normals = true: the file's vertex normals are used", at(node)));
                }
            }
            "rectangle" | "cube" => {
                shape.insert("type".into(), kind.into());
            }
            "sphere" => {
                let center = self.vector(node, "center")?.unwrap_or(Vec3::ZERO);
                let radius = self.float(node, "radius")?.unwrap_or(1.0);
                let local = Mat4::from_translation(center) * Mat4::from_scale(Vec3::splat(radius));
                if Sphere::new(m * local, false).is_ok() {
                    shape.insert("type".into(), "sphere".into());
                    shape.insert("center".into(), floats(&center.to_array()));
                    shape.insert("radius".into(), num(radius));
                } else {
                    // tessera's UV sphere has its poles on y, Mitsuba's sphere on z.
                    shape.insert("type".into(), "uv_sphere".into());
                    shape.insert("segments".into(), Value::Integer(512));
                    shape.insert("rings".into(), Value::Integer(256));
                    m *= local * Mat4::from_axis_angle(Vec3::X, std::f32::consts::FRAC_PI_2);
                    self.skip(format!(
                        "{}: a sphere whose to_world is not a similarity is rendered as a 512 x 256 \
                         ellipsoid mesh (Mitsuba renders a sphere)",
                        at(node)
                    ));
                }
            }
            other => {
                self.skip(format!("{}: shape type '{other}' is not translated (left out)", at(node)));
                return Ok(());
            }
        }
        if m != Mat4::IDENTITY {
            let step: Table = [("matrix".to_string(), floats(&m.transpose().to_cols_array()))].into_iter().collect();
            shape.insert("transform".into(), Value::Array(vec![Value::Table(step)]));
        }
        if self.boolean(node, "flip_normals") {
            shape.insert("flip_normals".into(), Value::Boolean(true));
        }
        for child in node.children().filter(|c| c.is_element()) {
            match child.tag_name().name() {
                "bsdf" => {
                    if let Some(name) = self.bsdf(child)? {
                        shape.insert("material".into(), name.into());
                    }
                }
                "ref" => {
                    let id = self.attr(child, "id").unwrap_or_default();
                    let name =
                        self.ids.get(&id).ok_or_else(|| format!("{}: <ref id=\"{id}\"> is undefined", at(node)))?;
                    shape.insert("material".into(), name.clone().into());
                }
                "emitter" if child.attribute("type") == Some("area") => {
                    let radiance = self.color(child, "radiance")?.unwrap_or(Value::Float(1.0));
                    if radiance.is_str() {
                        self.skip(format!("{}: a textured radiance is not translated (1 instead)", at(child)));
                        shape.insert("emission".into(), Value::Float(1.0));
                    } else {
                        shape.insert("emission".into(), radiance);
                    }
                }
                "emitter" => self.skip(format!("{}: only area emitters attach to shapes (left out)", at(child))),
                _ => {}
            }
        }
        self.shapes.push(shape);
        Ok(())
    }

    fn emitter(&mut self, node: Node) -> Parsed<()> {
        let kind = node.attribute("type").unwrap_or_default();
        let to_world = self.to_world(node)?;
        let m = to_world.unwrap_or(Mat4::IDENTITY);
        let mut light = Table::new();
        let vec3 = |v: Vec3| floats(&v.to_array());
        match kind {
            "constant" => {
                let radiance = self.color(node, "radiance")?.unwrap_or(Value::Float(1.0));
                let env: Table = [("type".to_string(), Value::from("constant")), ("radiance".into(), radiance)]
                    .into_iter()
                    .collect();
                self.scene.insert("environment".into(), Value::Table(env));
                return Ok(());
            }
            "envmap" => {
                let f = self.string(node, "filename").ok_or_else(|| format!("{}: no filename", at(node)))?;
                let mut env = Table::new();
                env.insert("type".into(), "envmap".into());
                env.insert("filename".into(), self.file(&f).into());
                if let Some(scale) = self.float(node, "scale")? {
                    env.insert("scale".into(), num(scale));
                }
                if to_world.is_some_and(|m| !m.abs_diff_eq(Mat4::IDENTITY, 1e-6)) {
                    self.skip(format!("{}: a turned environment map is rendered unturned", at(node)));
                }
                self.scene.insert("environment".into(), Value::Table(env));
                return Ok(());
            }
            "point" => {
                let position = self.vector(node, "position")?.unwrap_or_else(|| m.transform_point3(Vec3::ZERO));
                light.insert("type".into(), "point".into());
                light.insert("position".into(), vec3(position));
                light.insert("intensity".into(), self.color(node, "intensity")?.unwrap_or(Value::Float(1.0)));
            }
            "spot" => {
                light.insert("type".into(), "spot".into());
                light.insert("position".into(), vec3(m.transform_point3(Vec3::ZERO)));
                light.insert("direction".into(), vec3(m.transform_vector3(Vec3::Z)));
                light.insert("intensity".into(), self.color(node, "intensity")?.unwrap_or(Value::Float(1.0)));
                for key in ["cutoff_angle", "beam_width"] {
                    if let Some(v) = self.float(node, key)? {
                        light.insert(key.into(), num(v));
                    }
                }
            }
            "directional" => {
                let direction = self.vector(node, "direction")?.unwrap_or_else(|| m.transform_vector3(Vec3::Z));
                light.insert("type".into(), "directional".into());
                light.insert("direction".into(), vec3(direction));
                light.insert("irradiance".into(), self.color(node, "irradiance")?.unwrap_or(Value::Float(1.0)));
            }
            other => {
                self.skip(format!("{}: emitter type '{other}' is not translated (left out)", at(node)));
                return Ok(());
            }
        }
        if ["intensity", "irradiance"].iter().any(|k| light.get(*k).is_some_and(Value::is_str)) {
            self.skip(format!("{}: a textured intensity is not translated (left out)", at(node)));
            return Ok(());
        }
        self.lights.push(light);
        Ok(())
    }
}
