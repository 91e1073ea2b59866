//! How the flags' list values are read: numbers, 3-vectors, 1-based indices, `LINK:X,Y,Z`
//! and `JOINT=VALUE`; each error is one line naming the value.

/// A list of numbers from the command line.
#[derive(Clone, Debug)]
pub(crate) struct Numbers(pub(crate) Vec<f64>);

/// A list of 1-based indices.
#[derive(Clone, Debug)]
pub(crate) struct Indices(pub(crate) Vec<usize>);

pub(crate) fn parse_numbers(s: &str) -> Result<Numbers, String> {
    let items: Vec<&str> = s
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .collect();
    if items.is_empty() {
        return Err("expected numbers separated by commas".into());
    }
    items
        .iter()
        .map(|t| match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(format!("`{t}` is not a finite number")),
        })
        .collect::<Result<Vec<f64>, String>>()
        .map(Numbers)
}

pub(crate) fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v = parse_numbers(s)?.0;
    <[f64; 3]>::try_from(v.as_slice()).map_err(|_| format!("expected 3 numbers, got {}", v.len()))
}

pub(crate) fn parse_indices(s: &str) -> Result<Indices, String> {
    let items: Result<Vec<usize>, String> = s
        .split(',')
        .map(|t| match t.trim().parse::<usize>() {
            Ok(i) if i >= 1 => Ok(i),
            _ => Err(format!("`{t}` is not an index (1, 2, ...)")),
        })
        .collect();
    let items = items?;
    if items.len() > 3 {
        return Err("expected at most 3 indices".into());
    }
    Ok(Indices(items))
}

pub(crate) fn parse_contact_at(s: &str) -> Result<(String, [f64; 3]), String> {
    let Some((link, at)) = s.rsplit_once(':') else {
        return Err(format!("expected LINK:X,Y,Z, got `{s}`"));
    };
    Ok((link.to_string(), parse_vec3(at)?))
}

pub(crate) fn parse_armature(s: &str) -> Result<(String, f64), String> {
    let Some((joint, value)) = s.split_once('=') else {
        return Err(format!("expected JOINT=VALUE, got `{s}`"));
    };
    match value.trim().parse::<f64>() {
        Ok(v) => Ok((joint.trim().to_string(), v)),
        Err(_) => Err(format!("`{value}` is not a number")),
    }
}
