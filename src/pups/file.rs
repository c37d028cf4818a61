//! Control points read from a file (paper 002's points placed by hand or by another tool).
//!
//! CSV: a header naming the columns, then one point per line. `x` and `y` are required (the
//! unit square, v up); `value` (grey) or `r`, `g`, `b` (colour), `label`, and `ox`, `oy`, `oz`
//! (orientation) are optional. JSON: an array of objects `{"x": .., "y": .., "value": ..,
//! "colour": [r, g, b], "label": .., "orientation": [x, y, z]}`, with the same optional keys.

use super::field::ControlPoints;
use super::points::MAX_POINTS;
use crate::error::{Error, Result};
use crate::files::read_bounded;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Largest points file read.
pub const MAX_POINTS_FILE_BYTES: u64 = 256 << 20;

/// One point of a JSON points file.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonPoint {
    x: f32,
    y: f32,
    value: Option<f32>,
    colour: Option<[f32; 3]>,
    label: Option<u32>,
    orientation: Option<[f32; 3]>,
}

/// Read the control points of `path` (`.csv` or `.json`), each checked: finite coordinates,
/// values and orientations; at least three points; at most [`MAX_POINTS`].
pub fn read_points(path: &Path) -> Result<ControlPoints> {
    let bytes = read_bounded(path, MAX_POINTS_FILE_BYTES, "a points file")?;
    let text = std::str::from_utf8(&bytes).map_err(|_| Error::scene(path, "a points file is UTF-8 text"))?;
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let points = match extension.as_deref() {
        Some("json") => parse_json(text).map_err(|msg| Error::scene(path, msg))?,
        Some("csv") => parse_csv(text).map_err(|msg| Error::scene(path, msg))?,
        _ => return Err(Error::scene(path, "a points file is .csv or .json")),
    };
    if points.positions.len() < 3 {
        return Err(Error::scene(path, format!("{} point(s): give at least three", points.positions.len())));
    }
    Ok(points)
}

fn parse_json(text: &str) -> std::result::Result<ControlPoints, String> {
    let list: Vec<JsonPoint> = serde_json::from_str(text).map_err(|e| format!("malformed points JSON: {e}"))?;
    if list.len() > MAX_POINTS {
        return Err(format!("{} points, over tessera's limit of {MAX_POINTS}", list.len()));
    }
    let mut points = ControlPoints::new(Vec::new(), Vec::new(), Vec::new());
    points.orientations.clear();
    for (i, p) in list.iter().enumerate() {
        if p.value.is_some() && p.colour.is_some() {
            return Err(format!("point {}: give a value or a colour, not both", i + 1));
        }
        let value = p.colour.map(Vec3::from).unwrap_or(Vec3::splat(p.value.unwrap_or(0.0)));
        let orientation = p.orientation.map_or(Vec3::ZERO, Vec3::from);
        push(&mut points, Vec2::new(p.x, p.y), value, p.label.unwrap_or(i as u32), orientation)
            .map_err(|msg| format!("point {}: {msg}", i + 1))?;
    }
    Ok(points)
}

fn parse_csv(text: &str) -> std::result::Result<ControlPoints, String> {
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else { return Err("an empty points file: give a header and points".into()) };
    let columns: Vec<String> = header.split(',').map(|c| c.trim().to_ascii_lowercase()).collect();
    let known = ["x", "y", "value", "r", "g", "b", "label", "ox", "oy", "oz"];
    if let Some(c) = columns.iter().find(|c| !known.contains(&c.as_str())) {
        return Err(format!("line 1: unknown column '{c}' (known: {})", known.join(", ")));
    }
    let at = |name: &str| columns.iter().position(|c| c == name);
    let (Some(x), Some(y)) = (at("x"), at("y")) else { return Err("line 1: the header needs columns x and y".into()) };
    let rgb = [at("r"), at("g"), at("b")];
    if rgb.iter().any(Option::is_some) && (rgb.iter().any(Option::is_none) || at("value").is_some()) {
        return Err("line 1: give a value column or all of r, g and b".into());
    }
    let mut points = ControlPoints::new(Vec::new(), Vec::new(), Vec::new());
    points.orientations.clear();
    for (n, line) in lines {
        if points.positions.len() >= MAX_POINTS {
            return Err(format!("more than tessera's limit of {MAX_POINTS} points"));
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        if fields.len() != columns.len() {
            return Err(format!("line {}: {} fields for {} columns", n + 1, fields.len(), columns.len()));
        }
        let number = |c: Option<usize>, default: f32| -> std::result::Result<f32, String> {
            match c {
                None => Ok(default),
                Some(c) => {
                    fields[c].parse::<f32>().map_err(|_| format!("line {}: '{}' is not a number", n + 1, fields[c]))
                }
            }
        };
        let value = match rgb {
            [Some(_), Some(_), Some(_)] => Vec3::new(number(rgb[0], 0.0)?, number(rgb[1], 0.0)?, number(rgb[2], 0.0)?),
            _ => Vec3::splat(number(at("value"), 0.0)?),
        };
        let label = match at("label") {
            None => points.positions.len() as u32,
            Some(c) => fields[c]
                .parse::<u32>()
                .map_err(|_| format!("line {}: label '{}' is not a whole number", n + 1, fields[c]))?,
        };
        let orientation = Vec3::new(number(at("ox"), 0.0)?, number(at("oy"), 0.0)?, number(at("oz"), 0.0)?);
        push(&mut points, Vec2::new(number(Some(x), 0.0)?, number(Some(y), 0.0)?), value, label, orientation)
            .map_err(|msg| format!("line {}: {msg}", n + 1))?;
    }
    Ok(points)
}

/// Append one point, checking it.
fn push(
    points: &mut ControlPoints,
    p: Vec2,
    value: Vec3,
    label: u32,
    orientation: Vec3,
) -> std::result::Result<(), String> {
    if !p.is_finite() {
        return Err(format!("position ({}, {}) is not finite", p.x, p.y));
    }
    if !value.is_finite() {
        return Err("its value is not finite".into());
    }
    if !orientation.is_finite() {
        return Err("its orientation is not finite".into());
    }
    points.positions.push(p);
    points.values.push(value);
    points.labels.push(label);
    points.orientations.push(orientation.try_normalize().unwrap_or(Vec3::ZERO));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(name: &str, text: &str) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        (dir, path)
    }

    #[test]
    fn csv_and_json_files_are_read() {
        let (_d, csv) = file(
            "p.csv",
            "x,y,r,g,b,label,ox,oy,oz\n0.1,0.2,1,0,0,3,1,0,0\n0.9,0.1,0,1,0,3,0,0,0\n0.5,0.8,0,0,1,4,0,2,0\n",
        );
        let points = read_points(&csv).unwrap();
        assert_eq!(points.positions[2], Vec2::new(0.5, 0.8));
        assert_eq!(points.values[0], Vec3::X);
        assert_eq!(points.labels, [3, 3, 4]);
        assert_eq!(points.orientations[2], Vec3::Y);
        let (_d, json) =
            file("p.json", r#"[{"x":0.1,"y":0.2,"value":0.5},{"x":0.9,"y":0.1},{"x":0.5,"y":0.8,"colour":[1,0,0]}]"#);
        let points = read_points(&json).unwrap();
        assert_eq!(points.values, [Vec3::splat(0.5), Vec3::ZERO, Vec3::X]);
        assert_eq!(points.labels, [0, 1, 2]);
    }

    #[test]
    fn bad_points_files_are_errors_naming_the_problem() {
        for (name, text, needle) in [
            ("empty.csv", "", "empty"),
            ("short.csv", "x,y\n0,0\n1,1\n", "at least three"),
            ("nan.csv", "x,y\n0,0\nnan,1\n1,0\n", "line 3: position"),
            ("text.csv", "x,y\n0,zero\n", "line 2: 'zero' is not a number"),
            ("columns.csv", "x,y,value\n0,0\n", "2 fields for 3 columns"),
            ("header.csv", "u,v\n0,0\n", "unknown column 'u'"),
            ("empty.json", "[]", "at least three"),
            ("bad.json", "{", "malformed"),
            ("both.json", r#"[{"x":0,"y":0,"value":1,"colour":[1,1,1]}]"#, "not both"),
            ("points.txt", "x,y\n", ".csv or .json"),
        ] {
            let (_d, path) = file(name, text);
            let msg = read_points(&path).unwrap_err().to_string();
            assert!(msg.contains(name) && msg.contains(needle), "{name}: {msg}");
        }
    }
}
