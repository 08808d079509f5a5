//! Names a user types (parameters, bearing coefficients, candidate effects, presets, strategies):
//! the one message for a name that is not there, listing the valid names and the nearest match.
//!
//! A bottom layer: it uses nothing of the crate, and every layer above (and every plugin crate,
//! the workflow and the CLI) says "no such name" through it.

/// Most names listed in full; beyond, the first ones and how many more (10⁵ bearings would
/// otherwise print a megabyte).
const MAX_LISTED: usize = 40;

/// The edit distance (Levenshtein, by characters, case-insensitive) between `a` and `b`.
fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().flat_map(char::to_lowercase).collect();
    let b: Vec<char> = b.chars().flat_map(char::to_lowercase).collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = (diagonal + usize::from(ca != cb)).min(above + 1).min(row[j] + 1);
            diagonal = above;
        }
    }
    row[b.len()]
}

/// The valid name nearest to `given`: the one fewest edits away (none when two are), when
/// those edits are at most two fifths of the longer name (at least one) — a typo or another
/// ending (`matrix` for `matrices`), not another word. A valid name differing only in case is
/// always nearest.
pub fn nearest<'a, S: AsRef<str>>(given: &str, valid: &'a [S]) -> Option<&'a str> {
    let close: Vec<(usize, &str)> = valid
        .iter()
        .map(|v| (distance(given, v.as_ref()), v.as_ref()))
        .filter(|(d, v)| *d <= (2 * given.chars().count().max(v.chars().count()) / 5).max(1))
        .collect();
    let best = close.iter().map(|c| c.0).min()?;
    // Two names equally near (`k_K3` for `k_K1` or `k_K2`): no guess, the list says both.
    match close.iter().filter(|c| c.0 == best).collect::<Vec<_>>().as_slice() {
        [only] => Some(only.1),
        _ => None,
    }
}

/// The valid names as a list to read: all of them, or the first 40 and how many
/// more; `(none)` when there are none.
pub fn listed<S: AsRef<str>>(valid: &[S]) -> String {
    if valid.is_empty() {
        return "(none)".to_string();
    }
    let shown: Vec<&str> = valid.iter().take(MAX_LISTED).map(AsRef::as_ref).collect();
    let more = valid.len().saturating_sub(MAX_LISTED);
    if more > 0 {
        format!("{}, … ({more} more)", shown.join(", "))
    } else {
        shown.join(", ")
    }
}

/// The message for `given`, which is not one of `valid` (`what`: what the names name, singular,
/// e.g. `parameter`): "no parameter named `k_DEE`; did you mean `k_DE`? The parameters are k_NDE,
/// k_DE". The name is shown as typed, control characters escaped.
pub fn unknown<S: AsRef<str>>(what: &str, given: &str, valid: &[S]) -> String {
    let shown: String = given.chars().take(80).flat_map(char::escape_debug).collect();
    let plural = if what.ends_with('s') {
        format!("{what}es")
    } else if let Some(stem) = what.strip_suffix('y').filter(|s| !s.ends_with(['a', 'e', 'o', 'u'])) {
        format!("{stem}ies")
    } else {
        format!("{what}s")
    };
    match nearest(given, valid) {
        Some(n) => {
            format!("no {what} named `{shown}`; did you mean `{n}`? The {plural} are: {}", listed(valid))
        }
        None => format!("no {what} named `{shown}`; the {plural} are: {}", listed(valid)),
    }
}

/// A serde message about an unknown key or value (`unknown field `bearng`, expected one of
/// `material`, `shaft`, …`; `unknown variant …`) with the nearest valid name added (`; did you
/// mean `bearing`?`); any other message as it is. Serde lists the valid names already; this
/// adds the one the user most likely meant, as [`unknown`] does.
pub fn with_serde_hint(message: &str) -> String {
    let hint = (|| {
        let rest = ["unknown field `", "unknown variant `"]
            .iter()
            .find_map(|p| message.find(p).map(|i| &message[i + p.len()..]))?;
        let (given, rest) = rest.split_once('`')?;
        let expected = rest.split_once("expected")?.1;
        let valid: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
        nearest(given, &valid).filter(|n| *n != given).map(|n| format!("; did you mean `{n}`?"))
    })();
    match hint {
        Some(h) => format!("{}{h}", message.trim_end()),
        None => message.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_is_a_typo_away_and_never_another_word() {
        let valid = ["k_NDE", "k_DE", "zone1"];
        assert_eq!(nearest("k_DEE", &valid), Some("k_DE"));
        assert_eq!(nearest("K_de", &valid), Some("k_DE"));
        assert_eq!(nearest("zone", &valid), Some("zone1"));
        assert_eq!(nearest("stiffness", &valid), None);
        assert_eq!(nearest("k_K3", &["k_K1", "k_K2"]), None);
        assert_eq!(nearest("matrix", &["matrices"]), Some("matrices"));
        assert_eq!(nearest("stainless", &["steel"]), None);
        assert_eq!(distance("kitten", "sitting"), 3);
    }

    #[test]
    fn the_message_names_the_nearest_and_lists_all() {
        assert_eq!(
            unknown("parameter", "k_DEE", &["k_NDE", "k_DE"]),
            "no parameter named `k_DEE`; did you mean `k_DE`? The parameters are: k_NDE, k_DE"
        );
        assert_eq!(
            unknown("parameter", "x", &["k_NDE", "k_DE"]),
            "no parameter named `x`; the parameters are: k_NDE, k_DE"
        );
        assert_eq!(
            with_serde_hint("unknown field `bearng`, expected one of `material`, `shaft`, `bearing`"),
            "unknown field `bearng`, expected one of `material`, `shaft`, `bearing`; did you mean `bearing`?"
        );
        assert_eq!(
            with_serde_hint("unknown field `zzz`, expected `a` or `b`"),
            "unknown field `zzz`, expected `a` or `b`"
        );
        assert!(unknown("strategy", "dampd", &["damped"]).ends_with("The strategies are: damped"));
        let many: Vec<String> = (0..45).map(|i| format!("k{i}")).collect();
        assert!(unknown("parameter", "q", &many).ends_with("k39, … (5 more)"));
    }
}
