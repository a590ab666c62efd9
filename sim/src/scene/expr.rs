//! A tiny arithmetic language for scene files: numbers, parameter names, `+ - * / ^`,
//! parentheses, and `sqrt sin cos tan atan asin acos abs`, `pi`.

use std::collections::BTreeMap;

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
}

/// Evaluates `expr` with `vars` bound.
pub fn eval(expr: &str, vars: &BTreeMap<String, f64>) -> Result<f64, ExprError> {
    let mut p = Parser {
        s: expr.as_bytes(),
        i: 0,
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
    fn unary(&mut self) -> Result<f64, ExprError> {
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
}
