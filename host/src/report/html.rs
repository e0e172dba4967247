//! The report page: one self-contained HTML document (inline CSS, inline SVG, PNGs as data:
//! URIs; no script, no external URL of any kind).

use std::fmt::Write;

/// `text` with the characters that mean something in HTML (`& < > " '`) escaped, safe in
/// element content and in quoted attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// The page's stylesheet: a grid of plots, the plot classes of [`super::svg`] and thumbnails.
const STYLE: &str = "\
body{font:14px/1.4 system-ui,sans-serif;margin:1.5em auto;max-width:1400px;padding:0 1em;color:#222}
h1{font-size:1.5em;margin:0 0 .3em}h2{font-size:1.15em;margin:1.4em 0 .4em;border-bottom:1px solid #ddd}
table.meta td{padding:1px 12px 1px 0;vertical-align:top}table.meta td:first-child{color:#666}
pre{background:#f6f6f6;padding:.6em;overflow-x:auto;font-size:12px}
.warning{background:#fff3cd;border:1px solid #e0c060;padding:.4em .7em;margin:.4em 0}
.plots{display:grid;grid-template-columns:repeat(auto-fill,minmax(400px,1fr));gap:10px}
.plots svg{width:100%;height:auto;background:#fff;border:1px solid #e4e4e4}
svg text{font-size:11px;fill:#333}svg .title{font-size:12px;font-weight:600}
svg .grid line{stroke:#eee}svg .frame{fill:none;stroke:#999}
svg .xtick line,svg .ytick line{stroke:#999}
polyline{fill:none;stroke-width:1.4;stroke-linejoin:round}
.estimate{stroke:#1f5fbf}.truth{stroke:#d9480f;stroke-dasharray:4 2}
.rms{stroke:#5c940d}.joint{stroke:#862e9c}.hyp-count{stroke:#0b7285}.hyp-score{stroke:#5f3dc4}
rect.lost{fill:#adb5bd;fill-opacity:.35}
.dropped line{stroke:#c92a2a;stroke-width:.8;stroke-dasharray:2 2}.dropped path{fill:#c92a2a}
.gap line{stroke:#f08c00;stroke-width:.8}.gap path{fill:#f08c00}
.threshold line{stroke:#c92a2a;stroke-dasharray:6 3}.threshold text{fill:#c92a2a;font-size:10px}
.key.estimate,.key.truth,.key.rms,.key.joint{stroke:none}
.key.estimate{fill:#1f5fbf}.key.truth{fill:#d9480f}.key.rms{fill:#5c940d}.key.joint{fill:#862e9c}
.key.hyp-count{stroke:none;fill:#0b7285}.key.hyp-score{stroke:none;fill:#5f3dc4}
.key.lost{fill:#adb5bd}.key.dropped{fill:#c92a2a}.key.gap{fill:#f08c00}
.status-searching{fill:#4dabf7}.status-tracking{fill:#40c057}.status-lost{fill:#f59f00}
.thumbs{display:flex;flex-wrap:wrap;gap:10px}
figure.thumb{margin:0;font-size:12px;color:#444}figure.thumb img{display:block;border:1px solid #ccc}
figure.thumb.lost figcaption{color:#c92a2a}
";

/// A report page under construction: sections are appended in order.
#[derive(Debug, Clone, Default)]
pub struct Page {
    body: String,
}

impl Page {
    /// A new, empty page.
    pub fn new() -> Page {
        Page::default()
    }

    /// A section heading.
    pub fn heading(&mut self, text: &str) {
        let _ = writeln!(self.body, "<h2>{}</h2>", escape(text));
    }

    /// A two-column table of (name, value) rows, both escaped.
    pub fn table(&mut self, rows: &[(&str, String)]) {
        self.body.push_str("<table class=\"meta\">\n");
        for (name, value) in rows {
            let _ = writeln!(
                self.body,
                "<tr><td>{}</td><td>{}</td></tr>",
                escape(name),
                escape(value)
            );
        }
        self.body.push_str("</table>\n");
    }

    /// Preformatted text, escaped.
    pub fn pre(&mut self, text: &str) {
        let _ = writeln!(self.body, "<pre>{}</pre>", escape(text));
    }

    /// A paragraph of text, escaped.
    pub fn paragraph(&mut self, text: &str) {
        let _ = writeln!(self.body, "<p>{}</p>", escape(text));
    }

    /// A highlighted warning, escaped.
    pub fn warning(&mut self, text: &str) {
        let _ = writeln!(self.body, "<p class=\"warning\">{}</p>", escape(text));
    }

    /// Markup that is already safe (built by this module's callers from escaped parts).
    pub fn raw(&mut self, markup: &str) {
        self.body.push_str(markup);
        self.body.push('\n');
    }

    /// The whole document, titled `title`.
    pub fn finish(self, title: &str) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <title>{}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n{}</body>\n</html>\n",
            escape(title),
            escape(title),
            self.body
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escape_covers_markup_and_quotes() {
        assert_eq!(
            escape(r#"<a href="x">Tom & 'Jerry'</a>"#),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/a&gt;"
        );
        assert_eq!(escape("plain 1.5 mm"), "plain 1.5 mm");
    }

    #[test]
    fn page_text_is_escaped() {
        let mut page = Page::new();
        page.table(&[("folder", "/tmp/<seq>".to_string())]);
        page.warning("a & b");
        let html = page.finish("report <x>");
        assert!(html.contains("/tmp/&lt;seq&gt;") && html.contains("a &amp; b"));
        assert!(html.contains("<title>report &lt;x&gt;</title>"));
        assert!(!html.contains("<seq>"));
    }
}
