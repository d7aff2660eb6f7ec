//! A throwaway PostgreSQL database: created beside the admin connection's database, dropped
//! (`WITH (FORCE)`) on drop.

use sqlx::postgres::PgConnection;
use sqlx::Connection;

/// A database `<prefix>_<uuid>` on the server of an admin URL; dropped on drop.
#[derive(Debug)]
pub struct ThrowawayDb {
    admin_url: String,
    name: String,
    /// URL of the fresh database (the admin URL with its database replaced).
    pub url: String,
}

impl ThrowawayDb {
    /// Create `<prefix>_<uuid>` through `admin_url` (e.g. `postgres://postgres@127.0.0.1/test`).
    pub async fn create(admin_url: &str, prefix: &str) -> Result<ThrowawayDb, sqlx::Error> {
        let mut conn = PgConnection::connect(admin_url).await?;
        let name = format!("{prefix}_{}", uuid::Uuid::new_v4().simple());
        let created = sqlx::query(&format!("CREATE DATABASE \"{name}\""))
            .execute(&mut conn)
            .await;
        let _ = conn.close().await;
        created?;
        Ok(ThrowawayDb {
            url: with_database(admin_url, &name),
            admin_url: admin_url.to_string(),
            name,
        })
    }

    pub fn name(&self) -> &str {
        &self.name
    }
}

/// Replace the database name (the path) of a `postgres://` URL, keeping its query.
pub fn with_database(url: &str, database: &str) -> String {
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

impl Drop for ThrowawayDb {
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
            tracing::warn!(database = %self.name, "could not drop the throwaway database");
            eprintln!("warning: could not drop throwaway database {}", self.name);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::with_database;

    #[test]
    fn replaces_only_the_database() {
        assert_eq!(
            with_database("postgres://u@h:5432/test?sslmode=disable", "x"),
            "postgres://u@h:5432/x?sslmode=disable"
        );
        assert_eq!(with_database("postgres://u@h", "x"), "postgres://u@h/x");
    }
}
