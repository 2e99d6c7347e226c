//! The JSON the commands print (`--json`; `accuracy --json`, an array of them)
//! and the studio's `/api/pixel` and `/api/diff` answer: one object with a
//! `"schema"` version.

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
