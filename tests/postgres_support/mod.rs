//! A fresh PostgreSQL database per test on the local server (127.0.0.1:5432, trust auth), dropped
//! when the test ends. If the server cannot be reached the test fails with a message saying so,
//! unless `RAILWEAR_SKIP_POSTGRES=1` (then the test returns early and prints that it skipped).
//! `RAILWEAR_TEST_POSTGRES_URL` names another admin connection (default: user `postgres`, then
//! `root`, database `test`).
#![allow(dead_code)]

use sqlx::postgres::PgConnection;
use sqlx::Connection;

/// A database `railwear_test_<random>` created for one test; dropped on drop.
pub struct TestDb {
    admin_url: String,
    name: String,
    /// URL of the fresh database.
    pub url: String,
}

fn candidates() -> Vec<String> {
    match std::env::var("RAILWEAR_TEST_POSTGRES_URL") {
        Ok(url) if !url.is_empty() => vec![url],
        _ => vec![
            "postgres://postgres@127.0.0.1:5432/test".into(),
            "postgres://root@127.0.0.1:5432/test".into(),
        ],
    }
}

/// Replace the database name (the path) of a `postgres://` URL.
fn with_database(url: &str, database: &str) -> String {
    let (base, query) = match url.split_once('?') {
        Some((b, q)) => (b, Some(q)),
        None => (url, None),
    };
    let scheme_end = base.find("://").map_or(0, |i| i + 3);
    let host_end = base[scheme_end..]
        .find('/')
        .map_or(base.len(), |i| scheme_end + i);
    let mut out = format!("{}/{database}", &base[..host_end]);
    if let Some(q) = query {
        out.push('?');
        out.push_str(q);
    }
    out
}

impl TestDb {
    /// Create a fresh database, or `None` when PostgreSQL is unreachable and
    /// `RAILWEAR_SKIP_POSTGRES=1`. Panics with a clear message when unreachable otherwise.
    pub async fn create(tag: &str) -> Option<TestDb> {
        let mut errors = Vec::new();
        for admin_url in candidates() {
            match PgConnection::connect(&admin_url).await {
                Ok(mut conn) => {
                    let name = format!("railwear_test_{tag}_{}", uuid::Uuid::new_v4().simple());
                    sqlx::query(&format!("CREATE DATABASE \"{name}\""))
                        .execute(&mut conn)
                        .await
                        .unwrap_or_else(|e| panic!("CREATE DATABASE {name} failed: {e}"));
                    let _ = conn.close().await;
                    let url = with_database(&admin_url, &name);
                    return Some(TestDb {
                        admin_url,
                        name,
                        url,
                    });
                }
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
}

impl Drop for TestDb {
    fn drop(&mut self) {
        // Drop may run inside a tokio runtime: use a runtime of our own on a plain thread.
        let (admin_url, name) = (self.admin_url.clone(), self.name.clone());
        let dropped = std::thread::spawn(move || {
            let rt = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .ok()?;
            rt.block_on(async move {
                let mut conn = PgConnection::connect(&admin_url).await.ok()?;
                sqlx::query(&format!("DROP DATABASE IF EXISTS \"{name}\" WITH (FORCE)"))
                    .execute(&mut conn)
                    .await
                    .ok()?;
                conn.close().await.ok()
            })
        })
        .join();
        if !matches!(dropped, Ok(Some(()))) {
            eprintln!("warning: could not drop test database {}", self.name);
        }
    }
}

/// `Some(db)` or return early from the test (skip only allowed by RAILWEAR_SKIP_POSTGRES=1).
#[macro_export]
macro_rules! fresh_db {
    ($tag:expr) => {
        match postgres_support::TestDb::create($tag).await {
            Some(db) => db,
            None => return,
        }
    };
}
