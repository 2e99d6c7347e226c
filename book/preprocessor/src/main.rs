//! The raystep book's mdBook preprocessor, run after `links` (which has replaced
//! the `{{#include}}`s by source text) and `katex` (which has replaced `$…$` and
//! `$$…$$` by MathML), book/book.toml says so. Two things:
//!
//! - Listings start at the left margin: every fenced code block loses the
//!   indentation all its lines share (an anchored include keeps its source's). A
//!   Rust listing whose last line is a lone `}` closing a block the listing never
//!   opened loses that line too.
//! - Markdown leaves the MathML alone: mdBook parses the chapter as Markdown after
//!   the preprocessors, text inside the `<math>` elements included, where `_…_` would
//!   become `<em>` (which ends the MathML early) and `\` one backslash. Inside
//!   `<math>`, ASCII punctuation in text becomes a character reference (`_` is
//!   `&#95;`), which Markdown turns back into the same character.
//!
//! mdBook's protocol: `supports RENDERER` answers with the exit status; otherwise
//! stdin holds `[context, book]` as JSON and stdout gets the book back.

use std::io::Read;

use serde_json::Value;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("supports") {
        return; // Markdown for any renderer.
    }
    let mut input = String::new();
    std::io::stdin()
        .read_to_string(&mut input)
        .expect("reading the book from stdin");
    let [_context, mut book]: [Value; 2] = serde_json::from_str::<Vec<Value>>(&input)
        .ok()
        .and_then(|pair| pair.try_into().ok())
        .expect("mdBook sends [context, book]");
    if let Some(items) = book.get_mut("items") {
        tidy_items(items);
    }
    serde_json::to_writer(std::io::stdout(), &book).expect("writing the book to stdout");
}

/// Every chapter of a list of book items, sub-chapters included.
fn tidy_items(items: &mut Value) {
    for item in items.as_array_mut().into_iter().flatten() {
        if let Some(chapter) = item.get_mut("Chapter") {
            if let Some(Value::String(content)) = chapter.get_mut("content") {
                *content = tidy(content);
            }
            if let Some(sub_items) = chapter.get_mut("sub_items") {
                tidy_items(sub_items);
            }
        }
    }
}

/// The leading spaces and tabs of a line.
fn indent(line: &str) -> &str {
    &line[..line.len() - line.trim_start_matches([' ', '\t']).len()]
}

/// A fence line: its indentation, character, length and info string.
fn fence(line: &str) -> Option<(usize, char, usize, &str)> {
    let rest = line.trim_start_matches(' ');
    let mark = rest.chars().next().filter(|c| *c == '`' || *c == '~')?;
    let length = rest.len() - rest.trim_start_matches(mark).len();
    let info = rest[length..].trim();
    // An info string after backticks holds no backtick (else it is inline code).
    let valid = length >= 3 && !(mark == '`' && info.contains('`'));
    valid.then_some((line.len() - rest.len(), mark, length, info))
}

/// A chapter with the body of every fenced code block dedented and the MathML
/// outside them protected.
fn tidy(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut prose = String::new();
    let mut lines = text.split_inclusive('\n');
    while let Some(line) = lines.next() {
        let Some((margin, mark, length, info)) = fence(line) else {
            prose.push_str(line);
            continue;
        };
        out.push_str(&protect_maths(&std::mem::take(&mut prose)));
        out.push_str(line);
        let mut body = Vec::new();
        let mut closing = None;
        for line in lines.by_ref() {
            match fence(line) {
                Some((_, m, l, "")) if m == mark && l >= length => {
                    closing = Some(line);
                    break;
                }
                _ => body.push(line),
            }
        }
        let rust = info.split([',', ' ']).next() == Some("rust");
        for line in dedent(body, margin, rust) {
            out.push_str(&line);
        }
        out.push_str(closing.unwrap_or(""));
    }
    out.push_str(&protect_maths(&prose));
    out
}

/// The text with ASCII punctuation in the text (not the tags) of every `<math>`
/// element written as character references; `&` stays, it starts KaTeX's own.
fn protect_maths(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(start) = rest.find("<math") {
        let Some(length) = rest[start..].find("</math>") else {
            break;
        };
        out.push_str(&rest[..start]);
        let mut in_tag = false;
        for c in rest[start..start + length].chars() {
            match c {
                '<' => in_tag = true,
                '>' => in_tag = false,
                _ => {}
            }
            if !in_tag && c != '>' && c.is_ascii_punctuation() && !"&#;".contains(c) {
                out.push_str(&format!("&#{};", c as u32));
            } else {
                out.push(c);
            }
        }
        rest = &rest[start + length..];
    }
    out.push_str(rest);
    out
}

/// A code block's lines without the indentation they all share beyond the fence's
/// own `margin` (a block in a list item keeps the item's indentation).
fn dedent(mut body: Vec<&str>, margin: usize, rust: bool) -> Vec<String> {
    if rust {
        drop_dangling_brace(&mut body);
    }
    let common = body
        .iter()
        .filter(|l| !l.trim().is_empty())
        .map(|l| indent(l))
        .reduce(|a, b| {
            let shared = a.bytes().zip(b.bytes()).take_while(|(x, y)| x == y).count();
            &a[..shared]
        })
        .unwrap_or("");
    if common.len() <= margin {
        return body.into_iter().map(str::to_string).collect();
    }
    body.into_iter()
        .map(|l| match l.strip_prefix(common) {
            Some(rest) => format!("{}{rest}", &common[..margin]),
            None => l.to_string(), // a blank line with less indentation
        })
        .collect()
}

/// Removes a last line `}` that closes a block the listing does not open: it is
/// less indented than every other line and the braces do not balance without it.
fn drop_dangling_brace(body: &mut Vec<&str>) {
    let Some(last) = body.iter().rposition(|l| !l.trim().is_empty()) else {
        return;
    };
    let balance: isize = body
        .iter()
        .map(|l| l.matches('{').count() as isize - l.matches('}').count() as isize)
        .sum();
    let depth = indent(body[last]).len();
    let others_deeper = body[..last]
        .iter()
        .filter(|l| !l.trim().is_empty())
        .all(|l| indent(l).len() > depth);
    if body[last].trim() == "}" && balance < 0 && others_deeper && last > 0 {
        body.truncate(last);
    }
}

#[cfg(test)]
mod tests {
    use super::tidy;

    #[test]
    fn a_listing_from_inside_a_function_starts_at_the_margin() {
        let text =
            "Text\n\n```rust\n        let a = 1;\n\n            if a {}\n        b\n```\nMore\n";
        assert_eq!(
            tidy(text),
            "Text\n\n```rust\nlet a = 1;\n\n    if a {}\nb\n```\nMore\n"
        );
    }

    #[test]
    fn a_closing_brace_the_listing_did_not_open_goes() {
        let text =
            "```rust\n        x += 1;\n        if x {\n            y();\n        }\n    }\n```\n";
        assert_eq!(tidy(text), "```rust\nx += 1;\nif x {\n    y();\n}\n```\n");
        // Code after the brace keeps it (and keeps its own indentation).
        let text = "```rust\n        a;\n    }\n    b;\n```\n";
        assert_eq!(tidy(text), "```rust\n    a;\n}\nb;\n```\n");
    }

    #[test]
    fn a_block_in_a_list_item_keeps_the_item_s_indentation() {
        let text = "1. Item\n\n   ```text\n       a\n         b\n   ```\n";
        assert_eq!(tidy(text), "1. Item\n\n   ```text\n   a\n     b\n   ```\n");
    }

    #[test]
    fn text_outside_fences_and_inline_code_stay() {
        let text = "    indented paragraph\n``` not a fence ``` here\n";
        assert_eq!(tidy(text), text);
        // A shorter fence inside a longer one is text of the block.
        let text = "~~~~\n  x\n  ~~~\n  y\n~~~~\n";
        assert_eq!(tidy(text), "~~~~\nx\n~~~\ny\n~~~~\n");
    }

    #[test]
    fn markdown_cannot_touch_the_text_of_maths() {
        let text = "A $x$: <span class=\"katex\"><math display=\"block\"><mi>k</mi><mo>*</mo>\
                    <annotation encoding=\"application/x-tex\">\\underbrace{k}_{a} &amp; \\\\</annotation>\
                    </math></span> *b*_c_\n```text\n<math>_x_</math>\n```\n";
        assert_eq!(
            tidy(text),
            "A $x$: <span class=\"katex\"><math display=\"block\"><mi>k</mi><mo>&#42;</mo>\
             <annotation encoding=\"application/x-tex\">&#92;underbrace&#123;k&#125;&#95;&#123;a&#125; &amp; &#92;&#92;</annotation>\
             </math></span> *b*_c_\n```text\n<math>_x_</math>\n```\n"
        );
    }
}
