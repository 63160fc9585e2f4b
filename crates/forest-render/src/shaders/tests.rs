use super::*;

fn names(c: &Composer, roots: &[&str]) -> Vec<String> {
    // Each module's first line, which names it in the test sources below.
    c.compose(roots)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("// module ").map(str::to_string))
        .collect()
}

#[test]
fn imports_come_first_once_each_and_their_lines_go() {
    let c = Composer::runtime()
        .with_module("a", "#import b\n#import c\n// module a\n")
        .with_module("b", "#import c\n// module b\n")
        .with_module("c", "// module c\n");
    assert_eq!(names(&c, &["a"]), ["c", "b", "a"]);
    assert_eq!(names(&c, &["c", "a"]), ["c", "b", "a"]);
    assert!(!c.compose(&["a"]).unwrap().contains("#import"));
}

#[test]
fn a_slot_imports_what_fills_it() {
    let c = Composer::runtime()
        .with_module("user", "#import count\n// module user\n")
        .with_module("count_on", "// module on\n");
    assert_eq!(names(&c, &["user"]), ["user"]);
    assert!(c.compose(&["user"]).unwrap().contains("fn count_enter"));
    let on = c.fill("count", "count_on");
    assert_eq!(names(&on, &["user"]), ["on", "user"]);
}

#[test]
fn unknown_imports_and_circles_are_named() {
    let c = Composer::runtime().with_module("a", "#import nowhere\n");
    match c.compose(&["a"]) {
        Err(ShaderError::UnknownImport { module, import, .. }) => {
            assert_eq!((module.as_str(), import.as_str()), ("a", "nowhere"));
        }
        other => panic!("{other:?}"),
    }
    let c = Composer::runtime()
        .with_module("a", "#import b\n")
        .with_module("b", "#import a\n");
    assert_eq!(
        c.compose(&["a"]),
        Err(ShaderError::Circle("a → b → a".into()))
    );
}

/// Every runtime module's imports name modules or slots, so every module composes alone.
#[test]
fn every_runtime_module_composes() {
    let c = Composer::runtime();
    for (name, source) in MODULES {
        let composed = c.compose(&[name]).unwrap();
        let own: String = source
            .split_inclusive('\n')
            .filter(|l| !l.starts_with("#import "))
            .collect();
        assert!(composed.ends_with(&own), "{name}");
        assert!(
            !composed.lines().any(|l| l.trim().starts_with("#import ")),
            "{name}"
        );
    }
}

/// The number(s) a `const NAME: TYPE = …;` line of `wgsl` gives (a scalar, or a vector's
/// components).
fn wgsl_const(wgsl: &str, name: &str) -> Vec<f32> {
    let line = wgsl
        .lines()
        .find(|l| l.starts_with(&format!("const {name}:")))
        .unwrap_or_else(|| panic!("no const {name}"));
    let value = line.split_once('=').unwrap().1.trim().trim_end_matches(';');
    let value = value
        .find('(')
        .map_or(value, |i| &value[i + 1..value.len() - 1]);
    value
        .split(',')
        .map(|x| x.trim().parse().unwrap_or_else(|_| panic!("{name}: {x:?}")))
        .collect()
}

#[test]
fn the_wind_shader_has_the_cpu_models_constants() {
    use forest_format::wind;
    for (name, value) in [
        ("WIND_TAU", vec![std::f32::consts::TAU]),
        ("WIND_BEND", vec![wind::BEND]),
        ("WIND_MAX_LEAN", vec![wind::MAX_LEAN]),
        ("WIND_FLUTTER", vec![wind::FLUTTER]),
        ("WIND_MAX_RELATIVE_HEIGHT", vec![wind::MAX_RELATIVE_HEIGHT]),
        ("WIND_GUST_PERIODS", wind::GUST_PERIODS.to_vec()),
    ] {
        assert_eq!(wgsl_const(WIND_WGSL, name), value, "{name}");
    }
}
