//! JSON text assembled from parts serialized on their own, exactly as `serde_json` would write
//! the whole: the page's sections and data.json's records are values of different types, each
//! serialized by itself, and placed in one document here.
//!
//! Indented text follows `serde_json`'s `PrettyFormatter` (two spaces): a value written on its
//! own and then placed at depth d is the same text with every line after the first indented by
//! 2·d more spaces (a JSON string holds no raw line break). Compact text needs no indentation.

/// `text` (indented JSON of one value) placed one level deeper.
fn nested(text: &str) -> String {
    text.replace('\n', "\n  ")
}

/// `s` as a JSON string.
pub fn string(s: &str) -> String {
    serde_json::to_string(s).expect("a string serializes")
}

/// An indented array of the indented values `items`.
pub fn array(items: &[String]) -> String {
    if items.is_empty() {
        return "[]".to_string();
    }
    let body: Vec<String> = items.iter().map(|i| format!("  {}", nested(i))).collect();
    format!("[\n{}\n]", body.join(",\n"))
}

/// The indented object `object` with the entry `key`: `value` (indented JSON) first.
pub fn prepend(object: &str, key: &str, value: &str) -> String {
    let entry = format!("  {}: {}", string(key), nested(value));
    match object.strip_prefix('{').and_then(|o| o.strip_suffix('}')) {
        Some("") => format!("{{\n{entry}\n}}"),
        Some(body) => format!("{{\n{entry},{body}}}"),
        None => panic!("not a JSON object: {object}"),
    }
}

/// The indented object `object` with the entry `key`: `value` (indented JSON) last.
pub fn append(object: &str, key: &str, value: &str) -> String {
    let entry = format!("  {}: {}", string(key), nested(value));
    match object.strip_prefix('{').and_then(|o| o.strip_suffix('}')) {
        Some("") => format!("{{\n{entry}\n}}"),
        Some(body) => format!(
            "{{{},\n{entry}\n}}",
            body.strip_suffix('\n').unwrap_or(body)
        ),
        None => panic!("not a JSON object: {object}"),
    }
}

/// The compact object `object` with the entry `key`: `value` (compact JSON) last.
pub fn append_compact(object: &str, key: &str, value: &str) -> String {
    match object.strip_prefix('{').and_then(|o| o.strip_suffix('}')) {
        Some("") => format!("{{{}:{value}}}", string(key)),
        Some(body) => format!("{{{body},{}:{value}}}", string(key)),
        None => panic!("not a JSON object: {object}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn pretty(v: &serde_json::Value) -> String {
        serde_json::to_string_pretty(v).unwrap()
    }

    #[test]
    fn parts_placed_read_as_the_whole_written_at_once() {
        let inner = json!({"a": [1, {"b": []}], "c": {}});
        let whole = json!({"a": 1, "x": inner, "z": [inner, inner]});
        let built = append(
            &append(&pretty(&json!({"a": 1})), "x", &pretty(&inner)),
            "z",
            &array(&[pretty(&inner), pretty(&inner)]),
        );
        assert_eq!(built, pretty(&whole));
        let tagged = prepend(&pretty(&json!({"b": {"c": 2}})), "a", &string("t"));
        assert_eq!(tagged, pretty(&json!({"a": "t", "b": {"c": 2}})));
        assert_eq!(prepend("{}", "a", &string("t")), pretty(&json!({"a": "t"})));
        assert_eq!(array(&[]), "[]");
        let compact = append_compact(r#"{"a":1}"#, "x", &inner.to_string());
        assert_eq!(compact, json!({"a": 1, "x": inner}).to_string());
        assert_ne!(append(&pretty(&json!({"a": 1})), "x", "2"), pretty(&whole));
    }
}
