//! Generated shapes (`sim::fields::generated`) are fields like any other:
//! named `gen:FAMILY:SEED` wherever a field is, and every one of them gets
//! a puck count on the TV by the placement rule, the same every time.

use sim::fields::generated::{Family, GeneratedShape};
use sim::fields::source::FieldSource;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::puck_rule::{rule_pucks, LEAST_PUCKS};
use sim::scenario::Arena;

fn tv() -> Arena {
    Arena::Screen(Box::new(ArenaSpec::tv75()))
}

#[test]
fn every_family_s_first_shapes_get_a_puck_count_on_the_tv() {
    let (mut counts, mut refused) = (Vec::new(), Vec::new());
    for shape in GeneratedShape::each_of(&Family::ALL, 0, 4) {
        let field: FieldSource = format!("gen:{shape}").parse().unwrap();
        assert_eq!(field, FieldSource::Generated(shape));
        match rule_pucks(&field, &tv()) {
            Ok(n) if n >= LEAST_PUCKS => counts.push(format!("{field} {n}")),
            Ok(n) => refused.push(format!("{field}: {n}")),
            Err(e) => refused.push(e.to_string()),
        }
    }
    println!("{}", counts.join("\n"));
    assert!(refused.is_empty(), "{refused:#?}");
}

#[test]
fn a_generated_field_loads_the_same_twice_and_names_its_errors() {
    let field: FieldSource = "gen:letter:12".parse().unwrap();
    assert_eq!(field.load().unwrap(), field.load().unwrap());
    assert_eq!(field.to_string(), "gen:letter:12");
    let e = "gen:blob:1".parse::<FieldSource>().unwrap_err().to_string();
    assert!(
        e.contains("\"gen:blob:1\"") && e.contains("gen:FAMILY:SEED"),
        "{e}"
    );
}
