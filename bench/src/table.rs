//! Markdown/JSON tables and their cells.

use super::*;

#[derive(Clone)]
pub(crate) enum Cell {
    Num(f64),
    Int(u64),
    Text(String),
}

impl Cell {
    pub(crate) fn text(s: impl Into<String>) -> Self {
        Cell::Text(s.into())
    }
    pub(crate) fn opt(x: Option<f64>) -> Self {
        x.map(Cell::Num).unwrap_or_else(|| Cell::text("-"))
    }
    pub(crate) fn render(&self) -> String {
        match self {
            Cell::Num(x) => fmt_num(*x),
            Cell::Int(n) => n.to_string(),
            Cell::Text(s) => s.replace('|', "\\|"),
        }
    }
    pub(crate) fn json(&self) -> Value {
        match self {
            Cell::Num(x) if x.is_finite() => json!(x),
            Cell::Num(_) => Value::Null,
            Cell::Int(n) => json!(n),
            Cell::Text(s) => json!(s),
        }
    }
}

/// Four significant digits; scientific below 1e-3 and at or above 1e6.
pub(crate) fn fmt_num(x: f64) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    if !(1e-3..1e6).contains(&a) {
        return format!("{x:.3e}");
    }
    let digits = (3 - a.log10().floor() as i32).max(0) as usize;
    format!("{x:.digits$}")
}

pub(crate) struct Table {
    pub(crate) title: String,
    /// (JSON key, header).
    pub(crate) columns: Vec<(&'static str, &'static str)>,
    pub(crate) rows: Vec<Vec<Cell>>,
    pub(crate) notes: Vec<String>,
}

impl Table {
    pub(crate) fn new(title: impl Into<String>, columns: &[(&'static str, &'static str)]) -> Self {
        Self {
            title: title.into(),
            columns: columns.to_vec(),
            rows: Vec::new(),
            notes: Vec::new(),
        }
    }
    pub(crate) fn row(&mut self, cells: Vec<Cell>) {
        self.rows.push(cells);
    }
    pub(crate) fn note(&mut self, s: impl Into<String>) {
        self.notes.push(s.into());
    }
    pub(crate) fn to_markdown(&self) -> String {
        let mut s = format!("### {}\n\n|", self.title);
        for (_, h) in &self.columns {
            s.push_str(&format!(" {h} |"));
        }
        s.push_str("\n|");
        for _ in &self.columns {
            s.push_str("---|");
        }
        s.push('\n');
        for r in &self.rows {
            s.push('|');
            for c in r {
                s.push_str(&format!(" {} |", c.render()));
            }
            s.push('\n');
        }
        if !self.notes.is_empty() {
            s.push('\n');
            for n in &self.notes {
                s.push_str(&format!("- {n}\n"));
            }
        }
        s
    }
    pub(crate) fn to_json(&self) -> String {
        let rows: Vec<Value> = self
            .rows
            .iter()
            .map(|r| {
                let mut m = serde_json::Map::new();
                for ((k, _), c) in self.columns.iter().zip(r) {
                    m.insert((*k).to_string(), c.json());
                }
                Value::Object(m)
            })
            .collect();
        json!({"table": self.title, "rows": rows, "notes": self.notes}).to_string()
    }
}

pub(crate) fn machine_note() -> String {
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into());
    format!(
        "machine: {cores} cores visible, 1-min load average {load} when the table was printed; \
         wall-clock numbers scale with the share of a core this process got"
    )
}
