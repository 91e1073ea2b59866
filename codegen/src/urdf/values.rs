//! Attribute values: numbers and vectors of numbers, with messages in plain words.
//!
//! Numbers are Rust's `f64` syntax, which also reads `NaN`, `inf` and `infinity` (in any case):
//! the model stage rejects non-finite values where they matter, naming the link or joint.

/// One number; the message names the offending text.
pub(super) fn number(text: &str) -> Result<f64, String> {
    let t = text.trim();
    t.parse::<f64>().map_err(|_| {
        if t.is_empty() {
            "is empty where a number is expected".to_string()
        } else {
            format!("`{t}` is not a number")
        }
    })
}

/// Exactly `N` numbers separated by whitespace.
pub(super) fn numbers<const N: usize>(text: &str) -> Result<[f64; N], String> {
    let words: Vec<&str> = text.split_whitespace().collect();
    if words.len() != N {
        return Err(format!(
            "`{}` holds {} number(s) where {N} are expected",
            text.trim(),
            words.len()
        ));
    }
    let mut out = [0.0; N];
    for (slot, word) in out.iter_mut().zip(&words) {
        *slot = number(word)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_parse_or_name_the_culprit() {
        assert_eq!(number(" 1.5e-3 "), Ok(1.5e-3));
        assert!(number("NaN").unwrap().is_nan());
        assert_eq!(number("-inf"), Ok(f64::NEG_INFINITY));
        assert_eq!(number("-1.57."), Err("`-1.57.` is not a number".into()));
        assert!(number("").unwrap_err().contains("empty"));
        assert_eq!(numbers::<3>("0 1\t2\n"), Ok([0.0, 1.0, 2.0]));
        let e = numbers::<3>("1 1 1 1").unwrap_err();
        assert!(e.contains("4 number(s) where 3"), "{e}");
        assert_eq!(
            numbers::<3>("1 x 2"),
            Err("`x` is not a number".to_string())
        );
    }
}
