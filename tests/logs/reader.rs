//! The block reader against a line-by-line reading of the same rules (the reader before blocks:
//! `read_until` a line end, `str::trim` and `str::parse` per field): on generated logs of
//! numbers, blanks, `\r`, stray commas and spaces, non-numbers, NaN, non-UTF-8 bytes and other
//! white space, both give the same rows (values bit for bit, lines) and the same first problem,
//! whatever the block size.

use accelcal::input::LogProblem;
use accelcal::input::csv::block::{Rows, parse_block};
use accelcal::input::csv::read::{CsvReader, LogText, open_blocks};
use proptest::prelude::*;

/// A row or its problem: (line, values' bits) or (line, problem).
type Outcome = Result<(u64, Vec<u64>), (Option<u64>, LogProblem)>;

const COLUMNS: [&str; 2] = ["t_s", "accel_m_s2"];

/// The rows of `text` (after the header `t_s,x,accel_m_s2`), read line by line.
fn reference(text: &[u8]) -> Vec<Outcome> {
    let mut out = Vec::new();
    let mut line = 0u64;
    let mut header_seen = false;
    for raw in text.split_inclusive(|&b| b == b'\n') {
        line += 1;
        let end = raw
            .iter()
            .rposition(|&b| b != b'\n' && b != b'\r')
            .map_or(0, |i| i + 1);
        if raw[..end].iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        if !header_seen {
            header_seen = true;
            continue;
        }
        let Ok(text) = std::str::from_utf8(&raw[..end]) else {
            out.push(Err((Some(line), LogProblem::NotText)));
            return out;
        };
        let fields: Vec<&str> = text.split(',').map(str::trim).collect();
        if fields.len() != 3 {
            let problem = LogProblem::FieldCount {
                expected: 3,
                found: fields.len(),
                header: "t_s,x,accel_m_s2".to_string(),
            };
            out.push(Err((Some(line), problem)));
            return out;
        }
        let mut values = Vec::new();
        for (column, field) in COLUMNS.into_iter().zip([fields[0], fields[2]]) {
            let text = field.to_string();
            match field.parse::<f64>() {
                Ok(x) if x.is_finite() => values.push(x.to_bits()),
                Ok(_) => {
                    out.push(Err((Some(line), LogProblem::NotFinite { column, text })));
                    return out;
                }
                Err(_) => {
                    out.push(Err((Some(line), LogProblem::NotANumber { column, text })));
                    return out;
                }
            }
        }
        out.push(Ok((line, values)));
    }
    out
}

/// The rows of `text` through the row-by-row reader.
fn by_rows(text: &[u8]) -> Vec<Outcome> {
    let src = LogText::new("a.csv", text.to_vec());
    let mut reader = CsvReader::open(&src, COLUMNS).expect("the header reads");
    let mut out = Vec::new();
    loop {
        match reader.next_row() {
            Ok(Some((line, v))) => out.push(Ok((line, v.map(f64::to_bits).to_vec()))),
            Ok(None) => return out,
            Err(e) => {
                out.push(Err((e.line, e.problem)));
                return out;
            }
        }
    }
}

/// The rows of `text` through blocks of about `target` bytes.
fn by_blocks(text: &[u8], target: usize) -> Vec<Outcome> {
    let src = LogText::new("a.csv", text.to_vec());
    let (layout, mut feed) = open_blocks(&src, COLUMNS).expect("the header reads");
    let mut out = Vec::new();
    loop {
        let block = match feed.next_block(target, 1 << 16) {
            Ok(Some(b)) => b,
            Ok(None) => return out,
            Err(e) => {
                out.push(Err((e.line, e.problem)));
                return out;
            }
        };
        let mut rows = Rows::default();
        let result = parse_block(&layout, &block, &mut rows);
        for (v, &line) in rows.values.iter().zip(&rows.lines) {
            out.push(Ok((line, v.map(f64::to_bits).to_vec())));
        }
        if let Err(e) = result {
            out.push(Err((e.line, e.problem)));
            return out;
        }
    }
}

/// A field: mostly numbers, sometimes something else.
fn field() -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        6 => (-1e6f64..1e6).prop_map(|x| x.to_string().into_bytes()),
        2 => (0u32..1000).prop_map(|x| format!("{x}").into_bytes()),
        1 => Just(b"1e-7".to_vec()),
        1 => Just(b" 2.5 ".to_vec()),
        1 => Just(b"\xc2\xa03".to_vec()),
        1 => Just(b"NaN".to_vec()),
        1 => Just(b"x1".to_vec()),
        1 => Just(b"".to_vec()),
        1 => Just(b"\xff".to_vec()),
        1 => Just(b"+.5".to_vec()),
    ]
}

/// A line: three fields as a rule, sometimes blank or with another count, with `\n` or `\r\n`.
fn line() -> impl Strategy<Value = Vec<u8>> {
    let fields = prop_oneof![10 => Just(3usize), 1 => 0usize..5];
    (fields, prop::collection::vec(field(), 5), any::<bool>()).prop_map(|(n, f, crlf)| {
        let mut l = f[..n].join(&b","[..]);
        if n == 0 {
            l = b"  ".to_vec();
        }
        l.extend_from_slice(if crlf { b"\r\n" } else { b"\n" });
        l
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn blocks_read_as_lines_do(
        lines in prop::collection::vec(line(), 0..40),
        target in 1usize..200,
        unterminated in any::<bool>(),
    ) {
        let mut text = b"t_s,x,accel_m_s2\n".to_vec();
        for l in &lines {
            text.extend_from_slice(l);
        }
        if unterminated && text.ends_with(b"\n") {
            text.pop();
        }
        let expected = reference(&text);
        prop_assert_eq!(&by_rows(&text), &expected);
        prop_assert_eq!(&by_blocks(&text, target), &expected);
    }
}
