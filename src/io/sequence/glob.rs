//! Wildcard matching of file names (`*`, `?`, `[abc]`, `[a-z]`, `[!a-z]`).

/// Check a wildcard pattern for an unclosed `[`.
pub(super) fn check_glob(p: &[char]) -> Result<(), String> {
    let mut i = 0;
    while i < p.len() {
        if p[i] == '[' {
            match class_end(p, i) {
                Some(end) => i = end,
                None => return Err("unclosed `[` in the wildcard pattern".to_string()),
            }
        }
        i += 1;
    }
    Ok(())
}

/// Index of the `]` closing the class opened at `open` (a `]` right after `[`, `[!` or
/// `[^` is a member, as in the shell).
fn class_end(p: &[char], open: usize) -> Option<usize> {
    let mut j = open + 1;
    if matches!(p.get(j), Some('!' | '^')) {
        j += 1;
    }
    if p.get(j) == Some(&']') {
        j += 1;
    }
    while j < p.len() {
        if p[j] == ']' {
            return Some(j);
        }
        j += 1;
    }
    None
}

/// Whether `c` is in the class `p[open..=end]`.
fn class_matches(p: &[char], open: usize, end: usize, c: char) -> bool {
    let mut j = open + 1;
    let negate = matches!(p.get(j), Some('!' | '^'));
    if negate {
        j += 1;
    }
    let mut found = false;
    let mut first = true;
    while j < end {
        let lo = p[j];
        if !first && lo == ']' {
            break;
        }
        first = false;
        if j + 2 < end && p[j + 1] == '-' {
            let hi = p[j + 2];
            if lo <= c && c <= hi {
                found = true;
            }
            j += 3;
        } else {
            if lo == c {
                found = true;
            }
            j += 1;
        }
    }
    found != negate
}

/// Shell-style wildcard match of a whole file name: `*` (any run), `?` (one character),
/// `[abc]`, `[a-z]`, `[!a-z]` / `[^a-z]`. Iterative with backtracking to the last `*`, so
/// linear-ish and never exponential.
pub(super) fn glob_match(p: &[char], s: &[char]) -> bool {
    let (mut pi, mut si) = (0usize, 0usize);
    let mut star: Option<(usize, usize)> = None;
    while si < s.len() {
        let step = match p.get(pi) {
            Some('*') => {
                star = Some((pi, si));
                pi += 1;
                continue;
            }
            Some('?') => Some(pi + 1),
            Some('[') => match class_end(p, pi) {
                Some(end) if class_matches(p, pi, end, s[si]) => Some(end + 1),
                Some(_) => None,
                None => (s[si] == '[').then_some(pi + 1),
            },
            Some(&c) => (c == s[si]).then_some(pi + 1),
            None => None,
        };
        match step {
            Some(next) => {
                pi = next;
                si += 1;
            }
            None => match star {
                Some((sp, ss)) => {
                    pi = sp + 1;
                    si = ss + 1;
                    star = Some((sp, ss + 1));
                }
                None => return false,
            },
        }
    }
    p[pi..].iter().all(|&c| c == '*')
}
