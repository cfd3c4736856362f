//! The text form of named choices. A choice (`annulus`, `letter:T`,
//! `robot:cfg.json`, `tv75`, `reference`, ...) is parsed by its `FromStr`
//! and printed by its `Display`, written once each; [`text_form!`] derives
//! from them what serde needs to read and write it as a string
//! (`#[serde(try_from = "String", into = "String")]`), so config files,
//! checkpoints, the CLI and Python all spell a choice one way.

/// Implements `TryFrom<String>` (through `FromStr`) and `From<T> for
/// String` (through `Display`) for each type given, for
/// `#[serde(try_from = "String", into = "String")]`.
#[macro_export]
macro_rules! text_form {
    ($($ty:ty),+ $(,)?) => {$(
        impl ::core::convert::TryFrom<::std::string::String> for $ty {
            type Error = <$ty as ::core::str::FromStr>::Err;

            fn try_from(s: ::std::string::String) -> ::core::result::Result<$ty, Self::Error> {
                s.parse()
            }
        }

        impl ::core::convert::From<$ty> for ::std::string::String {
            fn from(value: $ty) -> ::std::string::String {
                value.to_string()
            }
        }
    )+};
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};
    use std::fmt;
    use std::str::FromStr;

    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(try_from = "String", into = "String")]
    struct Twice(u32);

    impl FromStr for Twice {
        type Err = String;
        fn from_str(s: &str) -> Result<Twice, String> {
            s.strip_prefix("twice:")
                .and_then(|n| n.parse().ok())
                .map(Twice)
                .ok_or_else(|| format!("not twice:N: {s:?}"))
        }
    }

    impl fmt::Display for Twice {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "twice:{}", self.0)
        }
    }

    crate::text_form!(Twice);

    #[test]
    fn a_named_choice_reads_and_writes_its_text_form_through_serde() {
        let json = serde_json::to_string(&Twice(7)).unwrap();
        assert_eq!(json, "\"twice:7\"");
        assert_eq!(serde_json::from_str::<Twice>(&json).unwrap(), Twice(7));
        let e = serde_json::from_str::<Twice>("\"thrice:7\"").unwrap_err();
        assert!(e.to_string().contains("not twice:N"), "{e}");
    }
}
