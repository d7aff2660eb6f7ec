//! Cursor pagination shared by every list endpoint: `?limit=N&cursor=C`, newest first.

use super::problem::Problem;
use crate::store::{Page, PageRequest};
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};

/// Largest page size.
pub const MAX_LIMIT: i64 = 100;
/// Page size when `limit` is not given.
pub const DEFAULT_LIMIT: i64 = 20;

/// Pagination query parameters (kept as text so a bad value gets a problem naming it).
#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct PageQuery {
    /// Items per page, 1..=100 (default 20).
    #[param(value_type = Option<i64>, minimum = 1, maximum = 100)]
    pub limit: Option<String>,
    /// `next_cursor` of the previous page.
    #[param(pattern = "^[1-9][0-9]{0,17}$")]
    pub cursor: Option<String>,
}

impl PageQuery {
    /// Validate into a store page request.
    pub fn to_request(&self) -> Result<PageRequest, Problem> {
        let limit = match &self.limit {
            None => DEFAULT_LIMIT,
            Some(text) => text
                .parse::<i64>()
                .ok()
                .filter(|n| (1..=MAX_LIMIT).contains(n))
                .ok_or_else(|| {
                    Problem::bad_parameter(
                        "limit",
                        format!("must be an integer in 1..={MAX_LIMIT}"),
                    )
                })?,
        };
        let after_seq = match &self.cursor {
            None => None,
            Some(text) => Some(text.parse::<i64>().ok().filter(|n| *n > 0).ok_or_else(|| {
                Problem::bad_parameter("cursor", "must be a next_cursor from a previous page")
            })?),
        };
        Ok(PageRequest { limit, after_seq })
    }
}

/// One page of a list.
#[derive(Debug, Serialize, ToSchema)]
pub struct PageView<T> {
    pub items: Vec<T>,
    /// Pass as `cursor` for the next page; null on the last page.
    pub next_cursor: Option<String>,
}

impl<T> PageView<T> {
    pub fn from_page<R>(page: Page<R>, f: impl FnMut(R) -> T) -> Self {
        PageView {
            items: page.items.into_iter().map(f).collect(),
            next_cursor: page.next_cursor,
        }
    }
}
