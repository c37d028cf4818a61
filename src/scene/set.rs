//! Scene values replaced from the command line (`tessera render --set camera.fov=40`), as
//! Mitsuba's `-D key=value` and pbrt's command-line overrides do: a dotted key path into the
//! scene file's TOML (array items as `shapes[0]`), and a TOML value (a number, a string, an
//! array, a boolean; text that is no TOML value is taken as a string). The scene is then read as
//! if the file said so, with the same checks.

/// Put `value` at `key` in the scene's TOML `table`: tables on the way are created where
/// missing, array items must exist. Errors say what is wrong with the key.
pub fn set_value(table: &mut toml::Table, key: &str, value: &str) -> Result<(), String> {
    let value = match toml::from_str::<toml::Table>(&format!("v = {value}")) {
        Ok(mut parsed) => parsed.remove("v").expect("parsed `v = ...`"),
        Err(_) => toml::Value::String(value.to_string()),
    };
    let segments: Vec<&str> = key.split('.').collect();
    let mut current = table;
    for (k, segment) in segments.iter().enumerate() {
        let last = k + 1 == segments.len();
        let (name, index) = match segment.split_once('[') {
            None => (*segment, None),
            Some((name, rest)) => {
                let index = rest
                    .strip_suffix(']')
                    .and_then(|i| i.parse::<usize>().ok())
                    .ok_or_else(|| format!("'{segment}' is not NAME or NAME[INDEX]"))?;
                (name, Some(index))
            }
        };
        if name.is_empty() {
            return Err(format!("'{key}' has an empty part"));
        }
        match index {
            None if last => {
                current.insert(name.to_string(), value);
                return Ok(());
            }
            None => {
                let next = current.entry(name).or_insert_with(|| toml::Value::Table(toml::Table::new()));
                current = next.as_table_mut().ok_or_else(|| format!("'{name}' is not a table"))?;
            }
            Some(i) => {
                let array = current
                    .get_mut(name)
                    .and_then(toml::Value::as_array_mut)
                    .ok_or_else(|| format!("'{name}' is not an array of the scene"))?;
                let len = array.len();
                let item = array.get_mut(i).ok_or_else(|| format!("'{name}' has {len} items, not an item {i}"))?;
                if last {
                    *item = value;
                    return Ok(());
                }
                current = item.as_table_mut().ok_or_else(|| format!("'{name}[{i}]' is not a table"))?;
            }
        }
    }
    Err(format!("'{key}' names no value"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> toml::Table {
        toml::from_str("[render]\nwidth = 64\n[[shapes]]\ntype = \"sphere\"\n[[shapes]]\ntype = \"obj\"\n").unwrap()
    }

    #[test]
    fn values_land_where_the_key_says() {
        let mut t = scene();
        set_value(&mut t, "render.width", "640").unwrap();
        set_value(&mut t, "camera.fov", "40.5").unwrap();
        set_value(&mut t, "shapes[1].filename", "meshes/cow.obj").unwrap();
        set_value(&mut t, "camera.eye", "[1, 2, 3]").unwrap();
        set_value(&mut t, "shapes[0].material", "\"quoted\"").unwrap();
        assert_eq!(t["render"]["width"].as_integer(), Some(640));
        assert_eq!(t["camera"]["fov"].as_float(), Some(40.5));
        assert_eq!(t["shapes"][1]["filename"].as_str(), Some("meshes/cow.obj"));
        assert_eq!(t["camera"]["eye"].as_array().map(Vec::len), Some(3));
        assert_eq!(t["shapes"][0]["material"].as_str(), Some("quoted"));
    }

    #[test]
    fn bad_keys_say_what_is_wrong() {
        let mut t = scene();
        for (key, needle) in [
            ("shapes[5].type", "2 items"),
            ("render[0]", "not an array"),
            ("render.width.x", "not a table"),
            ("shapes[x].type", "NAME[INDEX]"),
            ("camera..fov", "empty part"),
        ] {
            let msg = set_value(&mut t, key, "1").unwrap_err();
            assert!(msg.contains(needle), "{key}: {msg}");
        }
    }
}
