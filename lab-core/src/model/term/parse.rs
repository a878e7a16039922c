//! The term language's grammar (docs/interfaces.md, "Model file"): a
//! formula's text to its tree, every node with the byte span of its text
//! so an error names the place.
//!
//! ```text
//! expr    = sum
//! sum     = product (("+" | "-") product)*
//! product = unary (("*" | "/") unary)*
//! unary   = "-" unary | power
//! power   = atom ("^" unary)?            (right-associative: 2^3^2 = 2^9)
//! atom    = number | name | name "(" expr ")" | "lag" "(" expr "," expr ")"
//!         | ("ddt" | "d2dt2") "(" expr ("," expr)? ")" | "(" expr ")"
//! ```
//!
//! `-x^2` is `-(x^2)`, as in mathematics; a name followed by `(` is a
//! function (`abs sin cos exp step ddt d2dt2`, and `lag(x, tau)`: `x`
//! through a first-order lag of time constant `tau` s), any other name a
//! column of the run, a parameter, or `pi`. `ddt(x, h)` and `d2dt2(x, h)`
//! take their slopes over `h` s either side instead of the tool's default
//! (eval.rs).

use std::ops::Range;

/// A function of the language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    Abs,
    Sin,
    Cos,
    Exp,
    /// 0 below zero, 1 from zero.
    Step,
    /// The tool's filtered first derivative in time.
    Ddt,
    /// The tool's filtered second derivative in time.
    D2dt2,
    /// A first-order lag in time: `lag(x, tau)`, two arguments.
    Lag,
}

impl Func {
    pub const ALL: [Func; 8] = [
        Func::Abs,
        Func::Sin,
        Func::Cos,
        Func::Exp,
        Func::Step,
        Func::Ddt,
        Func::D2dt2,
        Func::Lag,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Func::Abs => "abs",
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Exp => "exp",
            Func::Step => "step",
            Func::Ddt => "ddt",
            Func::D2dt2 => "d2dt2",
            Func::Lag => "lag",
        }
    }

    fn from_name(s: &str) -> Option<Self> {
        Func::ALL.into_iter().find(|f| f.name() == s)
    }
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

impl Op {
    pub fn symbol(self) -> char {
        match self {
            Op::Add => '+',
            Op::Sub => '-',
            Op::Mul => '*',
            Op::Div => '/',
            Op::Pow => '^',
        }
    }

    /// Binding strength, for printing with the fewest parentheses.
    fn precedence(self) -> u8 {
        match self {
            Op::Add | Op::Sub => 1,
            Op::Mul | Op::Div => 2,
            Op::Pow => 4,
        }
    }
}

/// A node of a formula's tree.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Num(f64),
    /// A column, a parameter or `pi` (resolved against the run and the
    /// parameters when the term is checked).
    Name(String),
    Neg(Box<Node>),
    Bin(Op, Box<Node>, Box<Node>),
    Call(Func, Box<Node>),
    /// `lag(x, tau)`.
    Lag(Box<Node>, Box<Node>),
    /// `ddt(x, h)` or `d2dt2(x, h)`: the derivative with its slopes over
    /// `h` s either side.
    Within(Func, Box<Node>, Box<Node>),
}

/// A node and the byte span of its text in the formula.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub expr: Expr,
    pub span: Range<usize>,
}

/// A formula that does not parse: what, and the byte offset where.
#[derive(Clone, Debug, PartialEq)]
pub struct ParseError {
    pub offset: usize,
    pub msg: String,
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Name(String),
    Sym(char),
}

/// The formula's tokens with their byte spans.
fn tokens(s: &str) -> Result<Vec<(Tok, Range<usize>)>, ParseError> {
    let b = s.as_bytes();
    let mut out = vec![];
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            // An exponent: e or E, a sign, digits.
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                let mut j = i + 1;
                if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                    j += 1;
                }
                if j < b.len() && b[j].is_ascii_digit() {
                    while j < b.len() && b[j].is_ascii_digit() {
                        j += 1;
                    }
                    i = j;
                }
            }
            let text = &s[start..i];
            let v: f64 = text.parse().map_err(|_| ParseError {
                offset: start,
                msg: format!("`{text}` is not a number"),
            })?;
            out.push((Tok::Num(v), start..i));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push((Tok::Name(s[start..i].to_string()), start..i));
        } else if b"+-*/^(),".contains(&c) {
            out.push((Tok::Sym(c as char), i..i + 1));
            i += 1;
        } else {
            let ch = s[i..].chars().next().unwrap_or('?');
            return Err(ParseError {
                offset: i,
                msg: format!("`{ch}` is not part of the term language (numbers, names, + - * / ^, functions, parentheses)"),
            });
        }
    }
    Ok(out)
}

struct Parser<'a> {
    toks: Vec<(Tok, Range<usize>)>,
    at: usize,
    len: usize,
    text: &'a str,
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.at).map(|t| &t.0)
    }

    fn here(&self) -> usize {
        self.toks.get(self.at).map_or(self.len, |t| t.1.start)
    }

    fn is_sym(&self, c: char) -> bool {
        self.peek() == Some(&Tok::Sym(c))
    }

    fn error<T>(&self, msg: impl Into<String>) -> Result<T, ParseError> {
        Err(ParseError {
            offset: self.here(),
            msg: msg.into(),
        })
    }

    fn expected(&self, what: &str) -> ParseError {
        let found = match self.toks.get(self.at) {
            Some((_, r)) => format!("`{}`", &self.text[r.clone()]),
            None => "the end of the formula".into(),
        };
        ParseError {
            offset: self.here(),
            msg: format!("expected {what}, found {found}"),
        }
    }

    fn bin(op: Op, l: Node, r: Node) -> Node {
        let span = l.span.start..r.span.end;
        Node {
            expr: Expr::Bin(op, Box::new(l), Box::new(r)),
            span,
        }
    }

    fn sum(&mut self) -> Result<Node, ParseError> {
        let mut l = self.product()?;
        loop {
            let op = if self.is_sym('+') {
                Op::Add
            } else if self.is_sym('-') {
                Op::Sub
            } else {
                return Ok(l);
            };
            self.at += 1;
            let r = self.product()?;
            l = Self::bin(op, l, r);
        }
    }

    fn product(&mut self) -> Result<Node, ParseError> {
        let mut l = self.unary()?;
        loop {
            let op = if self.is_sym('*') {
                Op::Mul
            } else if self.is_sym('/') {
                Op::Div
            } else {
                return Ok(l);
            };
            self.at += 1;
            let r = self.unary()?;
            l = Self::bin(op, l, r);
        }
    }

    fn unary(&mut self) -> Result<Node, ParseError> {
        if self.is_sym('-') {
            let start = self.here();
            self.at += 1;
            let x = self.unary()?;
            let span = start..x.span.end;
            return Ok(Node {
                expr: Expr::Neg(Box::new(x)),
                span,
            });
        }
        self.power()
    }

    fn power(&mut self) -> Result<Node, ParseError> {
        let base = self.atom()?;
        if self.is_sym('^') {
            self.at += 1;
            let e = self.unary()?;
            return Ok(Self::bin(Op::Pow, base, e));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Node, ParseError> {
        let Some((tok, span)) = self.toks.get(self.at).cloned() else {
            return Err(self.expected("a number, a name or `(`"));
        };
        match tok {
            Tok::Num(v) => {
                self.at += 1;
                Ok(Node {
                    expr: Expr::Num(v),
                    span,
                })
            }
            Tok::Name(n) => {
                self.at += 1;
                if !self.is_sym('(') {
                    if Func::from_name(&n).is_some() {
                        return Err(ParseError {
                            offset: span.start,
                            msg: format!("`{n}` is a function: write `{n}(...)`"),
                        });
                    }
                    return Ok(Node {
                        expr: Expr::Name(n),
                        span,
                    });
                }
                let Some(f) = Func::from_name(&n) else {
                    let names: Vec<&str> = Func::ALL.iter().map(|f| f.name()).collect();
                    return Err(ParseError {
                        offset: span.start,
                        msg: format!(
                            "unknown function `{n}` (the functions are {})",
                            names.join(", ")
                        ),
                    });
                };
                self.at += 1;
                let arg = self.sum()?;
                let second = if f == Func::Lag {
                    if !self.is_sym(',') {
                        return Err(self.expected("`,` and the lag's time constant (lag(x, tau))"));
                    }
                    self.at += 1;
                    Some(self.sum()?)
                } else if matches!(f, Func::Ddt | Func::D2dt2) && self.is_sym(',') {
                    self.at += 1;
                    Some(self.sum()?)
                } else {
                    None
                };
                if !self.is_sym(')') {
                    return Err(self.expected("`)`"));
                }
                let end = self.toks[self.at].1.end;
                self.at += 1;
                Ok(Node {
                    expr: match second {
                        Some(tau) if f == Func::Lag => Expr::Lag(Box::new(arg), Box::new(tau)),
                        Some(h) => Expr::Within(f, Box::new(arg), Box::new(h)),
                        None => Expr::Call(f, Box::new(arg)),
                    },
                    span: span.start..end,
                })
            }
            Tok::Sym('(') => {
                self.at += 1;
                let inner = self.sum()?;
                if !self.is_sym(')') {
                    return Err(self.expected("`)`"));
                }
                let end = self.toks[self.at].1.end;
                self.at += 1;
                Ok(Node {
                    expr: inner.expr,
                    span: span.start..end,
                })
            }
            Tok::Sym(_) => Err(self.expected("a number, a name or `(`")),
        }
    }
}

/// Parses a formula.
pub fn parse(text: &str) -> Result<Node, ParseError> {
    let toks = tokens(text)?;
    let mut p = Parser {
        toks,
        at: 0,
        len: text.len(),
        text,
    };
    if p.toks.is_empty() {
        return p.error("an empty formula");
    }
    let n = p.sum()?;
    if p.at < p.toks.len() {
        return Err(p.expected("an operator or the end of the formula"));
    }
    Ok(n)
}

/// A number as the formula's text: shortest round trip.
fn number(v: f64) -> String {
    let s = format!("{v:?}");
    s.strip_suffix(".0").map_or(s.clone(), str::to_string)
}

/// The formula's text with the fewest parentheses that keep its tree.
pub fn to_text(n: &Node) -> String {
    fn go(n: &Node, out: &mut String, parent: u8, right_of: Option<Op>) {
        match &n.expr {
            Expr::Num(v) => {
                // A negative number binds like a negation.
                if *v < 0.0 && parent > 1 {
                    out.push('(');
                    out.push_str(&number(*v));
                    out.push(')');
                } else {
                    out.push_str(&number(*v));
                }
            }
            Expr::Name(s) => out.push_str(s),
            Expr::Neg(x) => {
                let paren = parent > 1;
                if paren {
                    out.push('(');
                }
                out.push('-');
                go(x, out, 3, None);
                if paren {
                    out.push(')');
                }
            }
            Expr::Call(f, x) => {
                out.push_str(f.name());
                out.push('(');
                go(x, out, 0, None);
                out.push(')');
            }
            Expr::Lag(x, tau) => {
                out.push_str("lag(");
                go(x, out, 0, None);
                out.push_str(", ");
                go(tau, out, 0, None);
                out.push(')');
            }
            Expr::Within(f, x, h) => {
                out.push_str(f.name());
                out.push('(');
                go(x, out, 0, None);
                out.push_str(", ");
                go(h, out, 0, None);
                out.push(')');
            }
            Expr::Bin(op, l, r) => {
                let p = op.precedence();
                // Left-associative + - * /: a right operand of the same
                // precedence needs parentheses (a - (b - c)); ^ is right-
                // associative: its left operand does.
                let paren = p < parent
                    || (p == parent
                        && match right_of {
                            Some(Op::Pow) => false,
                            Some(_) => true,
                            None => *op == Op::Pow,
                        });
                if paren {
                    out.push('(');
                }
                go(l, out, if *op == Op::Pow { p + 1 } else { p }, None);
                out.push_str(&format!(" {} ", op.symbol()));
                go(r, out, p, Some(*op));
                if paren {
                    out.push(')');
                }
            }
        }
    }
    let mut s = String::new();
    go(n, &mut s, 0, None);
    s.replace(" ^ ", "^")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Node {
        parse(s).unwrap_or_else(|e| panic!("{s}: {e:?}"))
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(to_text(&p("a + b * c")), "a + b * c");
        assert_eq!(to_text(&p("(a + b) * c")), "(a + b) * c");
        assert_eq!(to_text(&p("a - (b - c)")), "a - (b - c)");
        assert_eq!(to_text(&p("a - b - c")), "a - b - c");
        assert_eq!(to_text(&p("2^3^2")), "2^3^2");
        assert_eq!(to_text(&p("(2^3)^2")), "(2^3)^2");
        assert_eq!(to_text(&p("-x^2")), "-x^2");
        assert_eq!(to_text(&p("(-x)^2")), "(-x)^2");
        assert_eq!(to_text(&p("k_dph * w^2")), "k_dph * w^2");
        assert_eq!(to_text(&p("a / (b * c)")), "a / (b * c)");
        assert_eq!(
            to_text(&p("1.5e-3 * abs(w) * step(t - 600)")),
            "0.0015 * abs(w) * step(t - 600)"
        );
        // The written text parses back to the same tree (spans aside).
        for s in [
            "a - (b - c)",
            "-x^2",
            "(a + b)^-2",
            "exp(-t / tau_s) * a",
            "a * -b",
        ] {
            let once = to_text(&p(s));
            assert_eq!(to_text(&p(&once)), once, "{s}");
        }
    }

    #[test]
    fn errors_name_the_place() {
        let e = parse("k * (w + ").unwrap_err();
        assert_eq!(e.offset, 9);
        assert!(e.msg.contains("the end of the formula"), "{}", e.msg);
        let e = parse("k * sqrt(w)").unwrap_err();
        assert_eq!(e.offset, 4);
        assert!(e.msg.contains("unknown function `sqrt`"), "{}", e.msg);
        let e = parse("k * w $ 2").unwrap_err();
        assert_eq!(e.offset, 6);
        let e = parse("k w").unwrap_err();
        assert_eq!(e.offset, 2);
        let e = parse("abs + 1").unwrap_err();
        assert!(e.msg.contains("is a function"), "{}", e.msg);
        assert_eq!(parse("").unwrap_err().offset, 0);
        assert_eq!(parse("(a + b").unwrap_err().offset, 6);
    }
}
