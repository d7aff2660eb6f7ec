//! A fresh PostgreSQL database per test on the local server (127.0.0.1:5432, trust auth), dropped
//! when the test ends ([`railwear_testkit::ThrowawayDb`]). If the server cannot be reached the
//! test fails with a message saying so, unless `RAILWEAR_SKIP_POSTGRES=1` (then the test returns
//! early and prints that it skipped). `RAILWEAR_TEST_POSTGRES_URL` names another admin connection
//! (default: user `postgres`, then `root`, database `test`).
#![allow(dead_code)]

pub use railwear_testkit::ThrowawayDb as TestDb;

fn candidates() -> Vec<String> {
    match std::env::var("RAILWEAR_TEST_POSTGRES_URL") {
        Ok(url) if !url.is_empty() => vec![url],
        _ => vec![
            "postgres://postgres@127.0.0.1:5432/test".into(),
            "postgres://root@127.0.0.1:5432/test".into(),
        ],
    }
}

/// Create a fresh database `railwear_test_<tag>_<uuid>`, or `None` when PostgreSQL is
/// unreachable and `RAILWEAR_SKIP_POSTGRES=1`. Panics with a clear message when unreachable
/// otherwise.
pub async fn create(tag: &str) -> Option<TestDb> {
    let mut errors = Vec::new();
    for admin_url in candidates() {
        match TestDb::create(&admin_url, &format!("railwear_test_{tag}")).await {
            Ok(db) => return Some(db),
            Err(e) => errors.push(format!("{admin_url}: {e}")),
        }
    }
    if std::env::var("RAILWEAR_SKIP_POSTGRES").as_deref() == Ok("1") {
        eprintln!("skipped: PostgreSQL unreachable and RAILWEAR_SKIP_POSTGRES=1");
        return None;
    }
    panic!(
        "PostgreSQL is not reachable ({}). These tests need the server on 127.0.0.1:5432 \
         (trust auth, database `test`); set RAILWEAR_TEST_POSTGRES_URL to use another, or \
         RAILWEAR_SKIP_POSTGRES=1 to skip them.",
        errors.join("; ")
    );
}

/// `Some(db)` or return early from the test (skip only allowed by RAILWEAR_SKIP_POSTGRES=1).
#[macro_export]
macro_rules! fresh_db {
    ($tag:expr) => {
        match $crate::support::postgres::create($tag).await {
            Some(db) => db,
            None => return,
        }
    };
}
