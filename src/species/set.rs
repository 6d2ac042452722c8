//! Every species of a world, with the relations between them (seed 000's food, predator, kin,
//! mate) resolved by name once, when the world is built or a species is reloaded.

use super::*;
use crate::load::{locate, Diagnostic, Diagnostics};
use crate::perception::Relations;
use std::collections::BTreeMap;

/// Every species of a world, with relations resolved between them.
#[derive(Debug, Clone)]
pub struct SpeciesSet {
    /// Species by index ([`crate::world::SpeciesId`]).
    pub species: Vec<Arc<Species>>,
    /// What each species is to each other one.
    pub relations: Relations,
    /// Senses by species index.
    pub senses: Vec<SenseParams>,
}

impl SpeciesSet {
    /// Resolves relations between `species` (names must be unique, and every relation must name
    /// one of them).
    pub fn new(species: Vec<Arc<Species>>) -> Result<SpeciesSet, Diagnostics> {
        Self::with_library(species, |_| false)
    }

    /// Like [`SpeciesSet::new`], but a relation may also name a species that is not in this
    /// world as long as `exists(name)` says it is defined elsewhere (e.g. another file of the
    /// behaviors folder): a shark that eats sardines runs in a world without sardines.
    pub fn with_library(
        species: Vec<Arc<Species>>,
        exists: impl Fn(&str) -> bool,
    ) -> Result<SpeciesSet, Diagnostics> {
        let mut diags = Vec::new();
        let index: BTreeMap<&str, usize> = species
            .iter()
            .enumerate()
            .map(|(i, s)| (s.name.as_str(), i))
            .collect();
        if index.len() != species.len() {
            for (i, s) in species.iter().enumerate() {
                if index[s.name.as_str()] != i {
                    diags.push(Diagnostic::file(
                        &s.file,
                        format!("species name \"{}\" is used by two files", s.name),
                    ));
                }
            }
        }
        let n = species.len();
        let mut rel = Relations::new(n);
        for (i, s) in species.iter().enumerate() {
            let text = std::fs::read_to_string(&s.file).unwrap_or_default();
            let r = &s.def.relations;
            rel.set_eats_items(i, r.eats_items);
            rel.set_mates(i, r.mates);
            if r.see_others {
                for j in 0..n {
                    rel.set(i, j, Some(Category::Other));
                }
            }
            let mut resolve = |names: &Vec<String>, cat: Category, field: &str| {
                for name in names {
                    match index.get(name.as_str()) {
                        Some(&j) => rel.set(i, j, Some(cat)),
                        None if exists(name) => {}
                        None => {
                            let (l, c, _) =
                                locate(&text, &format!("\"{name}\""), 0).unwrap_or((0, 0, 0));
                            let known: Vec<&str> = index.keys().copied().collect();
                            diags.push(Diagnostic::new(
                                &s.file,
                                l,
                                c,
                                format!("unknown species \"{name}\" in `{field}`: loaded species are {}", known.join(", ")),
                                Some(&text),
                            ));
                        }
                    }
                }
            };
            resolve(&r.kin, Category::Kin, "kin");
            resolve(&r.prey, Category::Food, "prey");
            resolve(&r.predators, Category::Predator, "predators");
            rel.set(i, i, Some(Category::Kin));
        }
        if !diags.is_empty() {
            return Err(Diagnostics(diags));
        }
        let senses = species.iter().map(|s| s.senses).collect();
        Ok(SpeciesSet {
            species,
            relations: rel,
            senses,
        })
    }

    /// Index of the species named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.species.iter().position(|s| s.name == name)
    }
}
