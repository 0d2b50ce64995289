//! The pieces of the report pages (`report.html` of `bed`, of a series
//! and of `granule`): the page head and its one style sheet, escaping,
//! numbers rounded for tables, key-result and summary tables, warnings,
//! inline figures and glossaries of CSV columns. All text is
//! HTML-escaped.

use core::fmt::Write as _;

use serde_json::Value;

use crate::numbers::significant;

/// `text` with the HTML special characters escaped (for element content
/// and attribute values alike).
pub fn html_escape(text: &str) -> String {
    crate::output::escape_markup(text)
}

/// A JSON value as `summary.json` writes it: numbers with all their
/// digits, strings without quotes, `null` as "n/a".
fn show(value: &Value) -> String {
    match value {
        Value::Null => "n/a".to_string(),
        Value::String(s) => s.clone(),
        v => v.to_string(),
    }
}

/// A JSON value as the table's cell shows it: a float to
/// [`TABLE_DIGITS`] significant digits ([`significant`]), a list element
/// by element, anything else as [`show`] gives it.
fn shown_in_cell(value: &Value) -> String {
    match value {
        Value::Number(n) if !(n.is_u64() || n.is_i64()) => n
            .as_f64()
            .map_or_else(|| show(value), |x| significant(x, TABLE_DIGITS)),
        Value::Array(items) => {
            let items: Vec<String> = items.iter().map(shown_in_cell).collect();
            format!("[{}]", items.join(", "))
        }
        v => show(v),
    }
}

/// Significant digits of the floats in the report's tables; the cell's
/// `title` (shown on hover) and `summary.json` keep all of them.
pub const TABLE_DIGITS: usize = 4;

/// One row of a summary table.
#[derive(Debug)]
pub struct Row {
    /// The field, `outer.inner` for a nested one.
    pub key: String,
    /// What it means ("" if not listed).
    pub meaning: &'static str,
    /// As `summary.json` has it.
    pub full: String,
    /// As the cell shows it.
    pub cell: String,
}

impl Row {
    /// The row of `key` with its `meaning` and JSON `value`.
    pub fn new(key: String, meaning: &'static str, value: &Value) -> Self {
        Self {
            key,
            meaning,
            full: show(value),
            cell: shown_in_cell(value),
        }
    }
}

/// The fields of `summary` (a serialisable summary, a JSON object) as
/// rows: nested objects flattened one level (`kawakita.a`), those listed
/// in `fields` (key, meaning) first in its order — a field listed with an
/// empty meaning is shown elsewhere on the page and left out —, then the
/// others without a meaning, except those `skip` names (a scene shown as
/// TOML, say).
pub fn summary_rows(
    summary: &impl serde::Serialize,
    fields: &[(&str, &'static str)],
    skip: impl Fn(&str) -> bool,
) -> anyhow::Result<Vec<Row>> {
    let Value::Object(map) = serde_json::to_value(summary)? else {
        anyhow::bail!("the summary is not a JSON object");
    };
    let mut flat: Vec<(String, &Value)> = Vec::new();
    for (key, value) in &map {
        match value {
            Value::Object(inner) => {
                flat.extend(inner.iter().map(|(k, v)| (format!("{key}.{k}"), v)))
            }
            v => flat.push((key.clone(), v)),
        }
    }
    let known = |k: &str| fields.iter().any(|f| f.0 == k);
    let mut out: Vec<Row> = fields
        .iter()
        .filter(|f| !f.1.is_empty())
        .filter_map(|&(key, meaning)| {
            let v = flat.iter().find(|(k, _)| k == key)?.1;
            Some(Row::new(key.to_string(), meaning, v))
        })
        .collect();
    out.extend(
        flat.iter()
            .filter(|(k, _)| !known(k) && !skip(k))
            .map(|(k, v)| Row::new(k.clone(), "", v)),
    );
    Ok(out)
}

/// The summary table of `rows`: field, value (rounded; all digits on
/// hover) and meaning.
pub fn summary_table(rows: &[Row]) -> String {
    let mut h = String::from(
        "<h2>Summary</h2>\n<table>\n<tr><th>field</th><th>value</th><th>meaning</th></tr>\n",
    );
    for row in rows {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"value\" title=\"{}\">{}</td><td>{}</td></tr>",
            html_escape(&row.key),
            html_escape(&row.full),
            html_escape(&row.cell),
            html_escape(row.meaning)
        );
    }
    h.push_str("</table>\n");
    h
}

/// A short table of (what, value) pairs under `heading` (a page's key
/// results).
pub fn key_table(heading: &str, rows: &[(String, String)]) -> String {
    let mut h = format!("<h2>{}</h2>\n<table>\n", html_escape(heading));
    for (what, value) in rows {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"value\">{}</td></tr>",
            html_escape(what),
            html_escape(value)
        );
    }
    h.push_str("</table>\n");
    h
}

/// The warnings section: `error` (a run stopped early) first, then each
/// warning, or what `none` says when there is none.
pub fn warnings_section(error: Option<&str>, warnings: &[String], none: &str) -> String {
    let mut h = String::new();
    if let Some(e) = error {
        let _ = writeln!(
            h,
            "<p><strong>The run stopped early:</strong> {}</p>",
            html_escape(e)
        );
    }
    if warnings.is_empty() {
        let _ = writeln!(h, "<h2>Warnings</h2>\n<p>{}</p>", html_escape(none));
    } else {
        h.push_str(
            "<h2>Warnings</h2>\n<p>What the figures below hide (also in summary.json and on \
             stderr):</p>\n<ul>\n",
        );
        for w in warnings {
            let _ = writeln!(h, "<li>{}</li>", html_escape(w));
        }
        h.push_str("</ul>\n");
    }
    h
}

/// The start of a report page titled `title`, to its `<h1>`: the
/// document's head with the pages' one style sheet (shared by every
/// report page).
pub fn page_head(title: &str) -> String {
    let title = html_escape(title);
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{title}</title>\n\
         <style>\nbody {{ font-family: sans-serif; max-width: 960px; margin: 1em auto; padding: 0 1em; }}\n\
         table {{ border-collapse: collapse; }}\n\
         td, th {{ border: 1px solid #ccc; padding: 0.2em 0.6em; text-align: left; }}\n\
         td.value, td.num {{ font-family: monospace; }}\ntd.num {{ text-align: right; }}\n\
         tr.doubt td {{ background: #fff4e0; }}\n\
         figure {{ margin: 1em 0; }}\nfigure svg {{ max-width: 100%; height: auto; }}\n\
         pre {{ background: #f4f4f4; padding: 0.8em; overflow-x: auto; }}\n\
         p.caption {{ font-size: 0.9em; color: #444; margin-top: -0.4em; }}\n</style>\n</head>\n<body>\n\
         <h1>{title}</h1>\n"
    )
}

/// A float of the table: `x` to [`TABLE_DIGITS`] digits, "n/a" if none.
pub fn num(x: Option<f64>) -> String {
    x.map_or_else(|| "n/a".to_owned(), |x| significant(x, TABLE_DIGITS))
}

/// Why a fit's cell shows n/a ([`fit_cell`]).
pub const NO_FIT: &str = "no fit: too few rows in its window (the run ended before it) or no \
                          line through them";

/// A pressure of the table in kPa, from Pa.
pub fn kpa(x: Option<f64>) -> String {
    num(x.map(|p| p * 1e-3))
}

/// A fit's cell: its figure `value` (`None`: no fit — too few rows in
/// its window, as when the run ended before it, or no line through them),
/// marked ✗ if the run's summary rejects the fit, with its R² in the
/// cell's title.
pub fn fit_cell(value: Option<String>, r_squared: Option<f64>, ok: bool) -> String {
    let Some(value) = value else {
        return format!("<td class=\"num\" title=\"{NO_FIT}\">n/a</td>");
    };
    let title = format!("R² = {}", num(r_squared));
    let (class, mark) = if ok {
        ("num", "")
    } else {
        ("num doubt", " ✗")
    };
    format!(
        "<td class=\"{class}\" title=\"{}\">{}{mark}</td>",
        html_escape(&title),
        html_escape(&value)
    )
}

/// A picture as an image (not inline: a section picture holds thousands
/// of polygons): the file `path` (relative to the page) shown under the
/// alternative text `what: path`, captioned with links to it and to the
/// files `beside` it.
pub fn picture(path: &str, what: &str, beside: &[String]) -> String {
    let links: Vec<String> = core::iter::once(path)
        .chain(beside.iter().map(String::as_str))
        .map(|f| {
            let f = html_escape(f);
            format!("<a href=\"{f}\">{f}</a>")
        })
        .collect();
    let (path, what) = (html_escape(path), html_escape(what));
    format!(
        "<figure>\n<img src=\"{path}\" alt=\"{what}: {path}\" style=\"max-width: 100%\">\n\
         <figcaption>{}</figcaption>\n</figure>\n",
        links.join(", ")
    )
}

/// A glossary: the columns (name, meaning with its unit) of the table
/// `file`, under a heading, after the paragraph `about`.
pub fn glossary(file: &str, about: &str, columns: &[(&str, &str)]) -> String {
    let mut h = format!(
        "<h3>{}</h3>\n<p>{}</p>\n<table>\n<tr><th>column</th><th>meaning</th></tr>\n",
        html_escape(file),
        html_escape(about)
    );
    for (name, meaning) in columns {
        let _ = writeln!(
            h,
            "<tr><td class=\"value\">{}</td><td>{}</td></tr>",
            html_escape(name),
            html_escape(meaning)
        );
    }
    h.push_str("</table>\n");
    h
}

/// A plot inline: the SVG `svg`, captioned with a link to its file `href`
/// (relative to the page).
pub fn figure(href: &str, svg: &str) -> String {
    // The SVG is plotters' output: well-formed XML with its text already
    // escaped, so it is embedded as it is.
    let href = html_escape(href);
    format!("<figure>\n{svg}\n<figcaption><a href=\"{href}\">{href}</a></figcaption>\n</figure>\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell rounds floats to [`TABLE_DIGITS`] and keeps counts and text
    /// whole; the row's full value is what `summary.json` holds.
    #[test]
    fn cells_round_floats_only() {
        let float = serde_json::json!(0.123_456_789);
        let row = Row::new("x".into(), "", &float);
        assert_eq!(
            (row.full.as_str(), row.cell.as_str()),
            ("0.123456789", "0.1235")
        );
        let list = serde_json::json!([0.150_021_325, 0.300_003_8]);
        let row = Row::new("x".into(), "", &list);
        assert_eq!(
            (row.full.as_str(), row.cell.as_str()),
            ("[0.150021325,0.3000038]", "[0.1500, 0.3000]")
        );
        for (value, text) in [
            (serde_json::json!(1_234_567_u64), "1234567"),
            (serde_json::json!(-3), "-3"),
            (serde_json::json!(true), "true"),
            (serde_json::json!("0.5.0"), "0.5.0"),
            (Value::Null, "n/a"),
        ] {
            let row = Row::new("x".into(), "", &value);
            assert_eq!((row.full.as_str(), row.cell.as_str()), (text, text));
        }
    }

    #[test]
    fn escaping() {
        assert_eq!(
            html_escape("a<b & \"c\" 'd'>"),
            "a&lt;b &amp; &quot;c&quot; &#39;d&#39;&gt;"
        );
    }
}
