//! Every material colour of the IR's property table (`whitted_ir::properties`) written in a
//! scene reaches its own IR field, through a parent and an inline material too, and a
//! negative one is an error naming the property.

use whitted_ir::properties::MATERIAL_COLORS;
use whitted_ir::{Color, Material};

use crate::support::compile;

fn materials(source: &str) -> Vec<Material> {
    let compilation = compile(source);
    let Some(scene) = compilation.scene else {
        panic!("{source}: {:?}", compilation.diagnostics);
    };
    scene.materials.iter().map(|(_, m)| m.clone()).collect()
}

#[test]
fn every_material_colour_reaches_its_field() {
    let wanted = Color::new(0.25, 0.5, 0.75);
    for row in MATERIAL_COLORS {
        let name = row.name;
        let source = format!(
            "material parent {{ {name} <0.25, 0.5, 0.75> }}\n\
             sphere {{ material parent }}\n\
             sphere {{ material : parent {{ }} }}\n\
             sphere {{ material {{ {name} 0.5 }} }}\n"
        );
        let all = materials(&source);
        let set: Vec<&Material> = all.iter().filter(|m| (row.get)(m) == wanted).collect();
        assert!(set.len() >= 2, "`{name}`: {all:#?}");
        assert!(
            all.iter().any(|m| (row.get)(m) == Color::gray(0.5)),
            "`{name}` as a grey: {all:#?}"
        );
        // Nothing else moved from its default.
        for m in set {
            let mut expected = Material::default();
            (row.set)(&mut expected, wanted);
            expected.name.clone_from(&m.name);
            assert_eq!(*m, expected, "`{name}`");
        }
    }
}

#[test]
fn a_negative_material_colour_is_an_error_naming_it() {
    for row in MATERIAL_COLORS {
        let name = row.name;
        let compilation = compile(&format!("sphere {{ material {{ {name} <0, -1, 0> }} }}"));
        assert!(compilation.scene.is_none(), "`{name}` accepted -1");
        assert!(
            compilation
                .diagnostics
                .iter()
                .any(|d| d.message == format!("`{name}` cannot be negative")),
            "`{name}`: {:?}",
            compilation.diagnostics
        );
    }
}
