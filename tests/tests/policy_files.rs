//! The policy files the repository ships decode with the current format.

#[test]
fn shipped_policies_decode() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../policies");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "policy") {
            let bytes = std::fs::read(&path).unwrap();
            shared::PolicyBlob::decode(&bytes)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            count += 1;
        }
    }
    assert!(count > 0, "no .policy files in {}", dir.display());
}
