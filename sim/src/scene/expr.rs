//! A tiny arithmetic language for scene files: numbers, parameter names, `+ - * / ^`,
//! parentheses, and `sqrt sin cos tan atan asin acos abs`, `pi`.
//!
//! The parser is recursive descent with a nesting budget ([`MAX_DEPTH`]): parentheses, leading
//! signs and exponents nested deeper than that are a [`ExprError::TooDeep`], never a stack
//! overflow, however long the text.

use std::collections::BTreeMap;

/// How deeply an expression may nest: each parenthesis or function call, each leading sign and
/// each exponent opens one level.
pub const MAX_DEPTH: usize = 64;

/// Longest excerpt of an expression quoted in a nesting error [characters].
const QUOTED_CHARS: usize = 60;

/// Why an expression could not be evaluated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExprError {
    /// A syntax error.
    #[error("cannot parse `{expr}`: {what} at column {column}")]
    Syntax {
        /// The expression.
        expr: String,
        /// What is wrong.
        what: String,
        /// 1-based column.
        column: usize,
    },
    /// An unknown name.
    #[error("`{expr}` uses unknown name `{name}`")]
    UnknownName {
        /// The expression.
        expr: String,
        /// The name.
        name: String,
    },
    /// Nested deeper than [`MAX_DEPTH`].
    #[error("`{excerpt}`: nested deeper than {max_depth} levels (parentheses, signs, exponents) at column {column}")]
    TooDeep {
        /// The expression's start (at most 60 characters, then `…`).
        excerpt: String,
        /// The nesting budget.
        max_depth: usize,
        /// 1-based column where the budget ran out.
        column: usize,
    },
}

/// The parameter names an expression refers to (not `pi`, not function names), found
/// lexically with the parser's own rules for numbers and names; empty for text that is not
/// an expression's tokens.
pub fn names(expr: &str) -> Vec<String> {
    let s = expr.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let c = s[i];
        if c.is_ascii_digit() || c == b'.' {
            i += 1;
            while i < s.len()
                && (s[i].is_ascii_digit()
                    || matches!(s[i], b'.' | b'e' | b'E')
                    || (matches!(s[i], b'-' | b'+') && matches!(s[i - 1], b'e' | b'E')))
            {
                i += 1;
            }
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < s.len() && (s[i].is_ascii_alphanumeric() || s[i] == b'_') {
                i += 1;
            }
            let name = &expr[start..i];
            let mut j = i;
            while j < s.len() && s[j].is_ascii_whitespace() {
                j += 1;
            }
            let call = s.get(j) == Some(&b'(');
            if !call && name != "pi" {
                out.push(name.to_string());
            }
        } else {
            i += 1;
        }
    }
    out
}

/// Evaluates `expr` with `vars` bound.
pub fn eval(expr: &str, vars: &BTreeMap<String, f64>) -> Result<f64, ExprError> {
    let mut p = Parser {
        s: expr.as_bytes(),
        i: 0,
        depth: 0,
        expr,
        vars,
    };
    let v = p.sum()?;
    p.ws();
    if p.i != p.s.len() {
        return Err(p.err("unexpected input"));
    }
    Ok(v)
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    /// Current nesting, against [`MAX_DEPTH`].
    depth: usize,
    expr: &'a str,
    vars: &'a BTreeMap<String, f64>,
}

impl Parser<'_> {
    fn err(&self, what: &str) -> ExprError {
        ExprError::Syntax {
            expr: self.expr.to_string(),
            what: what.to_string(),
            column: self.i + 1,
        }
    }
    fn ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }
    fn peek(&mut self) -> Option<u8> {
        self.ws();
        self.s.get(self.i).copied()
    }
    fn sum(&mut self) -> Result<f64, ExprError> {
        let mut v = self.product()?;
        while let Some(c @ (b'+' | b'-')) = self.peek() {
            self.i += 1;
            let r = self.product()?;
            v = if c == b'+' { v + r } else { v - r };
        }
        Ok(v)
    }
    fn product(&mut self) -> Result<f64, ExprError> {
        let mut v = self.unary()?;
        while let Some(c @ (b'*' | b'/')) = self.peek() {
            self.i += 1;
            let r = self.unary()?;
            v = if c == b'*' { v * r } else { v / r };
        }
        Ok(v)
    }
    /// `atom ^ unary`: right-associative, binding tighter than a leading sign (−x^2 = −(x^2)).
    fn power(&mut self) -> Result<f64, ExprError> {
        let base = self.atom()?;
        if self.peek() == Some(b'^') {
            self.i += 1;
            let e = self.unary()?;
            return Ok(base.powf(e));
        }
        Ok(base)
    }
    /// Every recursion of the parser passes through here (a parenthesis, a call's argument, a
    /// sign, an exponent): the nesting budget is counted here.
    fn unary(&mut self) -> Result<f64, ExprError> {
        if self.depth >= MAX_DEPTH {
            let mut excerpt: String = self.expr.chars().take(QUOTED_CHARS).collect();
            if self.expr.chars().nth(QUOTED_CHARS).is_some() {
                excerpt.push('…');
            }
            return Err(ExprError::TooDeep {
                excerpt,
                max_depth: MAX_DEPTH,
                column: self.i + 1,
            });
        }
        self.depth += 1;
        let v = self.unary_at_depth();
        self.depth -= 1;
        v
    }
    fn unary_at_depth(&mut self) -> Result<f64, ExprError> {
        match self.peek() {
            Some(b'-') => {
                self.i += 1;
                Ok(-self.unary()?)
            }
            Some(b'+') => {
                self.i += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }
    fn atom(&mut self) -> Result<f64, ExprError> {
        match self.peek() {
            Some(b'(') => {
                self.i += 1;
                let v = self.sum()?;
                if self.peek() != Some(b')') {
                    return Err(self.err("expected `)`"));
                }
                self.i += 1;
                Ok(v)
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => {
                let start = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i].is_ascii_digit()
                        || self.s[self.i] == b'.'
                        || self.s[self.i] == b'e'
                        || self.s[self.i] == b'E'
                        || ((self.s[self.i] == b'-' || self.s[self.i] == b'+')
                            && matches!(self.s[self.i - 1], b'e' | b'E')))
                {
                    self.i += 1;
                }
                let text = &self.expr[start..self.i];
                text.parse::<f64>().map_err(|_| self.err("bad number"))
            }
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i].is_ascii_alphanumeric() || self.s[self.i] == b'_')
                {
                    self.i += 1;
                }
                let name = &self.expr[start..self.i];
                if self.peek() == Some(b'(') {
                    self.i += 1;
                    let arg = self.sum()?;
                    if self.peek() != Some(b')') {
                        return Err(self.err("expected `)`"));
                    }
                    self.i += 1;
                    let f: fn(f64) -> f64 = match name {
                        "sqrt" => f64::sqrt,
                        "sin" => f64::sin,
                        "cos" => f64::cos,
                        "tan" => f64::tan,
                        "atan" => f64::atan,
                        "asin" => f64::asin,
                        "acos" => f64::acos,
                        "abs" => f64::abs,
                        _ => {
                            return Err(ExprError::UnknownName {
                                expr: self.expr.to_string(),
                                name: name.to_string(),
                            })
                        }
                    };
                    return Ok(f(arg));
                }
                if name == "pi" {
                    return Ok(std::f64::consts::PI);
                }
                self.vars
                    .get(name)
                    .copied()
                    .ok_or_else(|| ExprError::UnknownName {
                        expr: self.expr.to_string(),
                        name: name.to_string(),
                    })
            }
            _ => Err(self.err("expected a number, a name or `(`")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_and_names() {
        let mut v = BTreeMap::new();
        v.insert("l_m".to_string(), 2.0);
        assert_eq!(eval("1 + 2 * 3", &v).unwrap(), 7.0);
        assert_eq!(eval("-(l_m - 0.5) ^ 2", &v).unwrap(), -2.25);
        assert_eq!(eval("sqrt(l_m * 8)", &v).unwrap(), 4.0);
        assert_eq!(eval("1e-3 * 2", &v).unwrap(), 2e-3);
    }

    #[test]
    fn errors_name_the_problem() {
        let v = BTreeMap::new();
        assert!(
            matches!(eval("x + 1", &v), Err(ExprError::UnknownName { name, .. }) if name == "x")
        );
        assert!(matches!(eval("1 +", &v), Err(ExprError::Syntax { .. })));
        assert!(matches!(eval("(1", &v), Err(ExprError::Syntax { .. })));
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_stack_overflow() {
        let v = BTreeMap::new();
        let deep = format!("{}1{}", "(".repeat(20_000), ")".repeat(20_000));
        assert!(matches!(
            eval(&deep, &v),
            Err(ExprError::TooDeep {
                max_depth: MAX_DEPTH,
                ..
            })
        ));
        let signs = format!("{}1", "-".repeat(50_000));
        let e = eval(&signs, &v).unwrap_err();
        assert!(matches!(e, ExprError::TooDeep { .. }), "{e}");
        assert!(
            e.to_string().len() < 200,
            "the message quotes an excerpt: {e}"
        );
        let powers = vec!["2"; 10_000].join("^");
        assert!(matches!(eval(&powers, &v), Err(ExprError::TooDeep { .. })));
        // Within the budget, nesting still works.
        let ok = format!("{}1{}", "(".repeat(30), ")".repeat(30));
        assert_eq!(eval(&ok, &v).unwrap(), 1.0);
        assert_eq!(eval(&format!("{}1", "-".repeat(40)), &v).unwrap(), 1.0);
    }

    #[test]
    fn names_are_the_parameters_an_expression_uses() {
        assert_eq!(
            names("sqrt(leg_m / g_m_s2) * 1e-3 + pi - x2^2 + 2E+3"),
            vec!["leg_m", "g_m_s2", "x2"]
        );
        assert!(names("1.5e-3").is_empty());
    }
}
