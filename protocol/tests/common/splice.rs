//! The generated sections of the docs: `<!-- generated:NAME -->…<!-- end:NAME -->`. Shared by
//! pen-protocol's docs test and pen-host's (`host-driver/tests/main.rs` includes this file).

/// `doc` with the section `name` replaced by `body`; panics naming a missing marker.
pub fn splice(doc: &str, name: &str, body: &str) -> String {
    let begin = format!("<!-- generated:{name} -->");
    let end = format!("<!-- end:{name} -->");
    let b = doc.find(&begin).unwrap_or_else(|| panic!("marker {begin} missing")) + begin.len();
    let e = doc[b..].find(&end).unwrap_or_else(|| panic!("marker {end} missing")) + b;
    format!("{}{}{}", &doc[..b], body, &doc[e..])
}
