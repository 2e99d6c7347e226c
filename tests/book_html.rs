//! The built book. Each test builds it into a temporary folder with the mdBook and
//! mdbook-katex that `.ci/run` pins (and book/preprocessor, which book/book.toml
//! runs with `cargo run`), then:
//!
//! - reads the HTML: every formula typeset as MathML (no `$` left over), every
//!   listing at the left margin, nothing loaded from another host;
//! - opens every page of SUMMARY.md in a real headless Chromium
//!   (`tests/browser/book.mjs`) with every request intercepted: no console error,
//!   no failed load, no request that leaves the machine, fractions and
//!   superscripts laid out as maths. One screenshot per page goes to
//!   `target/tmp/book-screenshots/` for a person to look at.
//!
//! Needs mdbook and mdbook-katex at the pinned versions in `$CARGO_HOME/bin`
//! (`.ci/run` installs them), and for the second test Chromium
//! (`apt-get install chromium`), Node.js and `npm ci --prefix tests/browser`.
//! Without them the tests are skipped, or fail under CI (where `CI` is set).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// The browser window, in CSS pixels (one screen pixel each).
const VIEWPORT: (u32, u32) = (1280, 900);

/// Listings longer than this many lines are reported (not failed).
const LONG_LISTING: usize = 40;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A version `.ci/run` pins, from its line `NAME=VERSION`.
fn pinned(name: &str) -> String {
    let run = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    run.lines()
        .find_map(|l| l.strip_prefix(&format!("{name}=")))
        .unwrap_or_else(|| panic!(".ci/run pins no {name}"))
        .to_string()
}

/// What `program --version` prints, if it runs.
fn version(program: &Path) -> Option<String> {
    let out = Command::new(program).arg("--version").output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The folder of mdbook and mdbook-katex at the pinned versions, or what is missing.
fn book_tools() -> Result<PathBuf, String> {
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cargo")))
        .ok_or("no CARGO_HOME or HOME")?;
    let bin = home.join("bin");
    let mut missing = Vec::new();
    for (program, pin, shown) in [
        ("mdbook", "MDBOOK_VERSION", "mdbook v"),
        ("mdbook-katex", "MDBOOK_KATEX_VERSION", "mdbook-katex "),
    ] {
        let want = format!("{shown}{}", pinned(pin));
        let found = version(&bin.join(program));
        if found.as_deref() != Some(want.as_str()) {
            missing.push(format!(
                "{want} in {} (found {found:?}; .ci/run installs it)",
                bin.display()
            ));
        }
    }
    if missing.is_empty() {
        Ok(bin)
    } else {
        Err(missing.join("; "))
    }
}

/// The book built into a temporary folder with the tools in `bin`.
fn build(bin: &Path) -> tempfile::TempDir {
    let out = tempfile::tempdir().unwrap();
    // mdbook finds mdbook-katex, and book/book.toml's `cargo run`, on the PATH.
    let cargo = std::env::var_os("CARGO").map(PathBuf::from);
    let mut path = vec![bin.to_path_buf()];
    path.extend(
        cargo
            .as_deref()
            .and_then(Path::parent)
            .map(Path::to_path_buf),
    );
    path.extend(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    ));
    let run = Command::new(bin.join("mdbook"))
        .arg("build")
        .arg(root().join("book"))
        .arg("--dest-dir")
        .arg(out.path())
        .env("PATH", std::env::join_paths(path).unwrap())
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "mdbook build failed:\n{log}");
    // Nothing to warn about, apart from mdbook-katex's note that it was built
    // against another patch release of mdBook's preprocessor crate.
    let worrying: Vec<&str> = log
        .lines()
        .filter(|l| l.contains("WARN") || l.contains("ERROR"))
        .filter(|l| !l.contains("was built against mdbook"))
        .collect();
    assert!(
        worrying.is_empty(),
        "mdbook build:\n{}",
        worrying.join("\n")
    );
    out
}

/// The pages of SUMMARY.md: (Markdown source, built HTML path relative to the book).
fn pages() -> Vec<(String, String)> {
    let summary = std::fs::read_to_string(root().join("chapters/SUMMARY.md")).unwrap();
    summary
        .lines()
        .filter_map(|line| {
            let start = line.find("](")? + 2;
            let name = &line[start..start + line[start..].find(')')?];
            let source = std::fs::read_to_string(root().join("chapters").join(name))
                .unwrap_or_else(|e| panic!("SUMMARY.md lists {name}: {e}"));
            Some((source, name.replace(".md", ".html")))
        })
        .collect()
}

/// Whether Markdown holds maths: a `$` outside code (fenced or inline).
fn has_maths(markdown: &str) -> bool {
    let mut in_fence = false;
    markdown.lines().any(|line| {
        if line.trim_start().starts_with("```") {
            in_fence = !in_fence;
            return false;
        }
        // Inline code spans are the odd-numbered pieces between backticks.
        !in_fence && line.split('`').step_by(2).any(|prose| prose.contains('$'))
    })
}

/// Text with the characters mdBook's HTML escapes put back.
fn unescape(html: &str) -> String {
    html.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&amp;", "&")
}

/// Text without its tags.
fn strip_tags(html: &str) -> String {
    let mut out = String::with_capacity(html.len());
    let mut in_tag = false;
    for c in html.chars() {
        match c {
            '<' => in_tag = true,
            '>' if in_tag => in_tag = false,
            c if !in_tag => out.push(c),
            _ => {}
        }
    }
    out
}

/// The contents of every `<open …>…</close>` element in `html`.
fn elements<'a>(html: &'a str, open: &str, close: &str) -> Vec<&'a str> {
    let mut found = Vec::new();
    let mut rest = html;
    while let Some(start) = rest.find(open) {
        let body = &rest[start..];
        let Some(end) = body.find(close) else { break };
        found.push(&body[body.find('>').unwrap() + 1..end]);
        rest = &body[end..];
    }
    found
}

/// `html` without the elements `<open …>…</close>`.
fn without(html: &str, open: &str, close: &str) -> String {
    let mut out = String::new();
    let mut rest = html;
    while let Some(start) = rest.find(open) {
        out.push_str(&rest[..start]);
        match rest[start..].find(close) {
            Some(end) => rest = &rest[start + end + close.len()..],
            None => return out,
        }
    }
    out.push_str(rest);
    out
}

/// Addresses from which a tag would load something from another host: `src`,
/// `srcset`, `poster` and `data` of any tag, `href` of `<link>` and of SVG's
/// `<image>`/`<use>` (a link, `<a href>`, loads nothing).
fn remote_loads(html: &str) -> Vec<String> {
    let mut found = Vec::new();
    for tag in html.split('<').skip(1) {
        let tag = &tag[..tag.find('>').unwrap_or(tag.len())];
        let name: String = tag
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect::<String>()
            .to_ascii_lowercase();
        let mut attributes = vec!["src=", "srcset=", "poster=", "data="];
        if ["link", "image", "use"].contains(&name.as_str()) {
            attributes.extend(["href=", "xlink:href="]);
        }
        for attribute in attributes {
            for (at, _) in tag.match_indices(attribute) {
                let preceded = tag[..at].ends_with(|c: char| c.is_whitespace());
                let value = tag[at + attribute.len()..].trim_start_matches(['"', '\'']);
                if preceded
                    && ["http:", "https:", "//"]
                        .iter()
                        .any(|p| value.to_ascii_lowercase().starts_with(p))
                {
                    found.push(format!("<{}…>", &tag[..tag.len().min(120)]));
                }
            }
        }
    }
    found
}

#[test]
fn the_built_book_typesets_its_maths_keeps_listings_at_the_margin_and_loads_nothing_from_elsewhere()
{
    let Some(bin) = common::required(book_tools(), "the book test") else {
        return;
    };
    let book = build(&bin);

    let mut long = Vec::new();
    let mut with_maths = 0;
    let mut listings = 0;
    for (source, page) in pages() {
        let html = std::fs::read_to_string(book.path().join(&page))
            .unwrap_or_else(|e| panic!("{page}: {e}"));
        let remote = remote_loads(&html);
        assert!(remote.is_empty(), "{page} loads from elsewhere: {remote:?}");
        assert!(
            html.contains("maths-"),
            "{page} does not link book/maths.css"
        );

        // Maths: typeset where the source has some, and no delimiter left over
        // (mdbook-katex leaves a formula it cannot typeset as it was).
        let main = &html[html.find("<main>").unwrap()..html.find("</main>").unwrap()];
        let prose = without(&without(main, "<pre", "</pre>"), "<code", "</code>");
        let prose = without(&prose, "<math", "</math>");
        assert!(
            !strip_tags(&prose).contains('$'),
            "{page}: a `$` outside code and maths (a formula KaTeX could not typeset?)"
        );
        if has_maths(&source) {
            with_maths += 1;
            assert!(main.contains("<math"), "{page}: no MathML");
        }
        for maths in elements(main, "<math", "</math>") {
            assert!(
                !maths.contains("<em>") && !maths.contains("<strong>"),
                "{page}: Markdown got into a formula: {maths}"
            );
        }

        // Listings: the indentation all lines of a code block share is gone.
        for code in elements(main, "<pre><code", "</code></pre>") {
            listings += 1;
            let text = unescape(&strip_tags(code));
            let lines: Vec<&str> = text.trim_end_matches('\n').lines().collect();
            let filled = lines.iter().filter(|l| !l.trim().is_empty());
            let common = filled
                .map(|l| l.len() - l.trim_start().len())
                .min()
                .unwrap_or(0);
            assert_eq!(
                common, 0,
                "{page}: a listing is indented by {common}:\n{text}"
            );
            if lines.len() > LONG_LISTING {
                long.push(format!("{page}: {} lines: {}", lines.len(), lines[0]));
            }
        }
    }
    assert!(with_maths >= 8, "{with_maths} pages with maths");
    // The chapters hold about a hundred listings: the markup was found.
    assert!(listings >= 50, "{listings} listings found");

    // The stylesheets and scripts the pages load do not load from elsewhere either.
    let (mut stylesheets, mut scripts) = (0, 0);
    for entry in walk(book.path()) {
        let is = |ext: &str| entry.extension().is_some_and(|e| e == ext);
        stylesheets += usize::from(is("css"));
        scripts += usize::from(is("js"));
        if is("css") || is("js") {
            let text = std::fs::read_to_string(&entry).unwrap();
            for (at, _) in text.match_indices("url(") {
                let value = text[at + 4..].trim_start_matches(['"', '\'', ' ']);
                assert!(
                    !value.starts_with("http") && !value.starts_with("//"),
                    "{} loads {}",
                    entry.display(),
                    &value[..value.len().min(80)]
                );
            }
            assert!(
                !text.contains("@import \"http") && !text.contains("@import url(http"),
                "{} imports from elsewhere",
                entry.display()
            );
        }
    }
    assert!(
        stylesheets >= 1 && scripts >= 1,
        "{stylesheets} stylesheets and {scripts} scripts in the built book"
    );
    if !long.is_empty() {
        eprintln!(
            "listings over {LONG_LISTING} lines:\n  {}",
            long.join("\n  ")
        );
    }
}

/// Every file under `dir`.
fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(walk(&path));
        } else {
            files.push(path);
        }
    }
    files
}

#[test]
fn every_page_of_the_built_book_renders_offline_in_chromium() {
    let Some(bin) = common::required(book_tools(), "the browser test of the book") else {
        return;
    };
    let Some(chromium) = common::required(common::browser_tools(), "the browser test of the book")
    else {
        return;
    };
    let book = build(&bin);
    let pages = pages();

    // Screenshots outside the sources, kept for a person to look at: in this
    // build's own temporary folder, so that two checkouts tested at once (or two
    // users) never clear each other's.
    let shots = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("book-screenshots");
    let _ = std::fs::remove_dir_all(&shots);
    std::fs::create_dir_all(&shots).unwrap();
    let mut browse = Command::new("node");
    browse
        .arg(root().join("tests/browser/book.mjs"))
        .arg("--book")
        .arg(book.path())
        .arg("--shots")
        .arg(&shots)
        .arg("--chromium")
        .arg(&chromium)
        .arg("--size")
        .arg(format!("{}x{}", VIEWPORT.0, VIEWPORT.1));
    for (_, page) in &pages {
        browse.arg(page);
    }
    let result = browse.output().unwrap();
    assert!(
        result.status.success(),
        "book.mjs failed:\n{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let report: Value = serde_json::from_slice(&result.stdout).unwrap_or_else(|e| {
        panic!("{e}: {}", String::from_utf8_lossy(&result.stdout));
    });
    let shown = report["pages"].as_array().unwrap();
    assert_eq!(shown.len(), pages.len());

    for ((source, page), shown) in pages.iter().zip(shown) {
        assert_eq!(shown["page"], page.as_str());
        // A clean page, offline: nothing logged, nothing failed, nothing refused.
        for key in [
            "console",
            "pageErrors",
            "failedRequests",
            "blocked",
            "badResponses",
        ] {
            assert_eq!(shown[key], serde_json::json!([]), "{page}: {key}");
        }
        assert!(shown["requests"].as_u64().unwrap() > 5, "{page}: requests");

        // The formulas are laid out as maths: stacked fractions, raised exponents.
        let maths = &shown["maths"];
        if has_maths(source) {
            assert!(maths["count"].as_u64().unwrap() > 0, "{page}: {maths}");
        }
        for key in ["flatFractions", "flatScripts", "width0"] {
            assert_eq!(maths[key], 0, "{page}: {key} in {maths}");
        }

        // The screenshot: a PNG of the window's size, not one flat colour.
        let path = PathBuf::from(shown["screenshot"].as_str().unwrap());
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        common::check_screenshot(&bytes, &path, VIEWPORT, 17);
    }
    eprintln!("screenshots: {}", shots.display());
}

#[test]
fn the_html_checks_catch_what_they_look_for() {
    let page = r#"<link rel="stylesheet" href="https://cdn.jsdelivr.net/katex.css">
        <link rel="stylesheet" href="css/general.css"><a href="https://example.org">a</a>
        <script src="//cdn.example/x.js"></script><img src="img/a.png">
        <math xmlns="http://www.w3.org/1998/Math/MathML"></math>"#;
    let found = remote_loads(page);
    assert_eq!(found.len(), 2, "{found:?}");
    assert!(found[0].contains("cdn.jsdelivr") && found[1].contains("cdn.example"));
    assert!(has_maths("Text $x$.\n"));
    assert!(!has_maths("`$ raystep`\n```text\n$ raystep check\n```\n"));
    assert_eq!(
        without("a<pre>b</pre>c<pre x>d</pre>e", "<pre", "</pre>"),
        "ace"
    );
    assert_eq!(
        elements("<code a>x</code><code>y</code>", "<code", "</code>"),
        ["x", "y"]
    );
}
