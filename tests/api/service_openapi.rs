//! `api/openapi.json` must equal what the code generates. To regenerate after an API change:
//! `cargo run -- openapi > api/openapi.json` (or run this test with RAILWEAR_UPDATE_OPENAPI=1).

use std::path::Path;

#[test]
fn openapi_document_in_api_dir_matches_the_code() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("api/openapi.json");
    let generated = railwear::http::openapi::openapi_json();
    if std::env::var_os("RAILWEAR_UPDATE_OPENAPI").is_some() {
        std::fs::write(&path, &generated).expect("write api/openapi.json");
    }
    let stored = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        stored == generated,
        "api/openapi.json is out of date: run `cargo run -- openapi > api/openapi.json` \
         (or RAILWEAR_UPDATE_OPENAPI=1 cargo test --test service_openapi)"
    );
    // The document is valid JSON naming every public resource.
    let doc: serde_json::Value = serde_json::from_str(&generated).expect("JSON");
    assert!(doc["openapi"].as_str().unwrap().starts_with("3."));
    for path in [
        "/v1/jobs",
        "/v1/jobs/{id}",
        "/v1/jobs/{id}/cancel",
        "/v1/jobs/{id}/tracks",
        "/v1/rails/{serial}/measurements",
        "/v1/rails/{serial}/report",
        "/v1/tokens",
    ] {
        assert!(doc["paths"].get(path).is_some(), "missing {path}");
    }
    assert!(doc["components"]["securitySchemes"]["bearer"].is_object());
}
