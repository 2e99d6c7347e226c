//! The JSON the commands print (`--json`; `accuracy --json`, an array of them)
//! and the studio's `/api/pixel` and `/api/diff` answer: one object with a
//! `"schema"` version; and the scene as `check --json` and `/api/scene` give it.

use crate::scene::{Role, Scene, Shape};

/// The version of every JSON object raystep prints (`"schema": 1`): it grows when
/// a field changes meaning or goes away, not when a field is added.
pub const JSON_SCHEMA: u32 = 1;

/// `value` (an object) with `"schema": 1` added, as JSON text (keys in
/// alphabetical order).
pub fn json_text(value: &impl serde::Serialize, pretty: bool) -> String {
    let mut object = serde_json::Map::new();
    object.insert("schema".into(), JSON_SCHEMA.into());
    match serde_json::to_value(value).expect("plain data serialises") {
        serde_json::Value::Object(fields) => object.extend(fields),
        other => {
            object.insert("data".into(), other);
        }
    }
    let object = serde_json::Value::Object(object);
    if pretty {
        serde_json::to_string_pretty(&object)
    } else {
        serde_json::to_string(&object)
    }
    .expect("plain data serialises")
}

/// A scene as `raystep check --json` prints it and the studio's `/api/scene`
/// answers it (without `"schema"`): what `raystep check` describes, as numbers,
/// `object_count`, and the list of `objects` only if `listed`.
pub fn scene_json(scene: &Scene, name: &str, listed: bool) -> serde_json::Value {
    use serde_json::json;
    let v = |v: crate::Vec3| json!([v.x, v.y, v.z]);
    let s = scene.camera().screen;
    let object = |o: &crate::scene::Object| {
        let m = &o.material;
        let material = json!({
            "ambient": v(m.ambient),
            "diffuse": v(m.diffuse),
            "specular": v(m.specular),
            "shininess": m.shininess,
            "reflection": m.reflection,
        });
        let entry = match o.role {
            Role::Sphere => "sphere",
            Role::Floor => "plane",
        };
        match o.shape {
            Shape::Sphere(sp) => json!({
                "entry": entry,
                "shape": "sphere",
                "center": v(sp.center),
                "radius": sp.radius,
                "material": material,
            }),
            Shape::Plane(p) => json!({
                "entry": entry,
                "shape": "plane",
                "point": v(p.point),
                "normal": v(p.normal),
                "material": material,
            }),
        }
    };
    let l = &scene.light;
    let mut described = json!({
        "scene": name,
        "valid": true,
        "width": scene.width,
        "height": scene.height,
        "max_depth": scene.max_depth,
        "camera": v(scene.camera),
        "screen": {
            "left": s.left,
            "right": s.right,
            "top": s.top,
            "bottom": s.bottom,
            "from_scene": scene.screen.is_some(),
        },
        "light": {
            "position": v(l.position),
            "ambient": v(l.ambient),
            "diffuse": v(l.diffuse),
            "specular": v(l.specular),
        },
        "spheres": scene.objects.iter().filter(|o| o.role == Role::Sphere).count(),
        "planes": scene.objects.iter().filter(|o| o.role == Role::Floor).count(),
        "object_count": scene.objects.len(),
    });
    if listed {
        described["objects"] = scene.objects.iter().map(object).collect();
    }
    described
}

#[cfg(test)]
mod tests {
    use super::*;

    /// README.md: every object has `"schema": 1`, keys in alphabetical order;
    /// `pretty` false is one line, true is indented over several.
    #[test]
    fn json_text_adds_schema_1_and_sorts_the_keys_on_one_line_or_indented() {
        let value = serde_json::json!({ "zeta": 2, "alpha": [1, 2] });
        assert_eq!(
            json_text(&value, false),
            r#"{"alpha":[1,2],"schema":1,"zeta":2}"#
        );
        assert_eq!(
            json_text(&value, true),
            "{\n  \"alpha\": [\n    1,\n    2\n  ],\n  \"schema\": 1,\n  \"zeta\": 2\n}"
        );
    }

    /// A value that is not an object is kept, under `data`, beside the schema.
    #[test]
    fn json_text_puts_a_value_that_is_no_object_under_data() {
        assert_eq!(json_text(&[1, 2], false), r#"{"data":[1,2],"schema":1}"#);
        assert_eq!(json_text(&"x", false), r#"{"data":"x","schema":1}"#);
    }
}
