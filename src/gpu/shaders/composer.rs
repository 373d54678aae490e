//! The composer of WGSL modules. WGSL has no modules, so each of our sources names the
//! modules whose declarations it uses in `#import NAME` lines, as vello's shaders do
//! (`vello_shaders/shader/shared/*.wgsl`), and the composer joins them into one
//! source: every module once, each after the modules it imports, the `#import` lines
//! removed. A module is specialised ([`super::super::features`]) before its imports are
//! read, so an import inside an `//#if` block is followed only when the block is kept.
//! Modules that import each other, directly or through others, are an error that
//! names the whole cycle.

use std::borrow::Cow;
use std::collections::BTreeSet;

use super::super::features::{DirectiveError, ShaderFeatures, kept_lines};

/// Why WGSL modules could not be composed: a bug in the shader sources (or in a
/// test's own kernel), which the tests catch for ours.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ComposeError {
    /// A module's feature directives are malformed.
    #[error("shader module `{module}`: {source}")]
    Directive {
        /// The module.
        module: String,
        /// What is wrong with its directives.
        #[source]
        source: DirectiveError,
    },
    /// No module has the name asked for.
    #[error("shader module `{module}` does not exist{}", imported_by(importer))]
    MissingModule {
        /// The name asked for.
        module: String,
        /// The module that imports it, `None` for the module composed.
        importer: Option<String>,
    },
    /// Modules import each other.
    #[error("shader modules import each other: {}", cycle.join(" -> "))]
    ImportCycle {
        /// The modules of the cycle in import order, the first repeated at the end
        /// (`a -> b -> a`).
        cycle: Vec<String>,
    },
    /// An `#import` line that is not `#import` and one module name.
    #[error("shader module `{module}`, line {line}: `#import` takes one module name")]
    MalformedImport {
        /// The module.
        module: String,
        /// The line, from 1.
        line: usize,
    },
}

fn imported_by(importer: &Option<String>) -> String {
    importer
        .as_ref()
        .map(|name| format!(" (imported by `{name}`)"))
        .unwrap_or_default()
}

/// Where the composer finds a module's source by its name.
pub(crate) type Lookup<'a> = &'a dyn Fn(&str) -> Option<Cow<'static, str>>;

/// The module named by an `#import` line, `None` for other lines, an error for an
/// `#import` without exactly one name of letters, digits and underscores.
fn import_of(module: &str, number: usize, line: &str) -> Result<Option<String>, ComposeError> {
    let Some(rest) = line.trim().strip_prefix("#import") else {
        return Ok(None);
    };
    let mut words = rest.split_whitespace();
    match (words.next(), words.next()) {
        (Some(name), None)
            if rest.starts_with(char::is_whitespace)
                && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') =>
        {
            Ok(Some(name.to_string()))
        }
        _ => Err(ComposeError::MalformedImport {
            module: module.to_string(),
            line: number,
        }),
    }
}

/// The names a module imports, in order, with `features` deciding its `//#if`
/// blocks.
pub(crate) fn imports_of(
    module: &str,
    source: &str,
    features: &ShaderFeatures,
) -> Result<Vec<String>, ComposeError> {
    let mut imports = Vec::new();
    for (number, line) in kept_lines(source, features).map_err(|e| directive(module, e))? {
        imports.extend(import_of(module, number, line)?);
    }
    Ok(imports)
}

fn directive(module: &str, source: DirectiveError) -> ComposeError {
    ComposeError::Directive {
        module: module.to_string(),
        source,
    }
}

/// One composition: the modules emitted so far and the chain of imports being
/// followed.
struct Composition<'a> {
    lookup: Lookup<'a>,
    features: &'a ShaderFeatures,
    /// The modules whose imports are being followed, the composed module first.
    path: Vec<String>,
    /// The modules already in `output`.
    done: BTreeSet<String>,
    output: String,
}

impl Composition<'_> {
    /// Emits `module` (whose text is `source`) after the modules it imports.
    fn add(&mut self, module: &str, source: &str) -> Result<(), ComposeError> {
        self.path.push(module.to_string());
        let mut body = String::with_capacity(source.len());
        for (number, line) in kept_lines(source, self.features).map_err(|e| directive(module, e))? {
            match import_of(module, number, line)? {
                Some(name) => self.import(&name, module)?,
                None => {
                    body.push_str(line);
                    body.push('\n');
                }
            }
        }
        self.path.pop();
        self.done.insert(module.to_string());
        self.output.push_str(&body);
        Ok(())
    }

    /// Emits the module `name` that `importer` imports, unless it is there already.
    fn import(&mut self, name: &str, importer: &str) -> Result<(), ComposeError> {
        if self.done.contains(name) {
            return Ok(());
        }
        if let Some(start) = self.path.iter().position(|m| m == name) {
            let mut cycle = self.path[start..].to_vec();
            cycle.push(name.to_string());
            return Err(ComposeError::ImportCycle { cycle });
        }
        let source = (self.lookup)(name).ok_or_else(|| ComposeError::MissingModule {
            module: name.to_string(),
            importer: Some(importer.to_string()),
        })?;
        self.add(name, &source)
    }
}

/// The WGSL extension the ray queries of `shaders/ray_query.wgsl` need. An `enable`
/// directive must precede every declaration of the whole source (naga refuses it
/// after the first), and the modules are emitted in their imports' order, so the
/// composition itself begins with it.
const RAY_QUERY_DIRECTIVE: &str = "enable wgpu_ray_query;\n";

/// The module `root`, whose text is `source`, composed with everything it imports
/// (found by `lookup`) and specialised to `features`; with
/// [`ShaderFeatures::hardware_traversal`] it begins with the ray-query extension's
/// `enable` directive.
pub(crate) fn compose(
    root: &str,
    source: &str,
    lookup: Lookup<'_>,
    features: &ShaderFeatures,
) -> Result<String, ComposeError> {
    let mut composition = Composition {
        lookup,
        features,
        path: Vec::new(),
        done: BTreeSet::new(),
        output: if features.hardware_traversal {
            RAY_QUERY_DIRECTIVE.to_string()
        } else {
            String::new()
        },
    };
    composition.add(root, source)?;
    Ok(composition.output)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Composes `root` from the synthetic `modules`.
    fn compose_from(
        modules: &'static [(&'static str, &'static str)],
        root: &str,
        features: &ShaderFeatures,
    ) -> Result<String, ComposeError> {
        let lookup = |name: &str| {
            modules
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, source)| Cow::Borrowed(*source))
        };
        let source = lookup(root).ok_or_else(|| ComposeError::MissingModule {
            module: root.to_string(),
            importer: None,
        })?;
        compose(root, &source, &lookup, features)
    }

    #[test]
    fn emits_each_module_once_after_its_imports() {
        const MODULES: &[(&str, &str)] = &[
            ("main", "#import b\n#import a\nfn main() {}\n"),
            ("a", "#import base\nfn a() {}\n"),
            ("b", "#import a\n#import base\nfn b() {}\n"),
            ("base", "const BASE: u32 = 1u;\n"),
        ];
        assert_eq!(
            compose_from(MODULES, "main", &ShaderFeatures::ALL).as_deref(),
            Ok("const BASE: u32 = 1u;\nfn a() {}\nfn b() {}\nfn main() {}\n")
        );
    }

    #[test]
    fn follows_only_the_imports_of_kept_blocks() {
        const MODULES: &[(&str, &str)] = &[
            (
                "main",
                "//#if REFRACTION\n#import glass\n//#else\n#import air\n//#endif\nfn main() {}\n",
            ),
            ("glass", "fn glass() {}\n"),
            ("air", "fn air() {}\n"),
        ];
        let without = ShaderFeatures {
            refraction: false,
            ..ShaderFeatures::ALL
        };
        assert_eq!(
            compose_from(MODULES, "main", &ShaderFeatures::ALL).as_deref(),
            Ok("fn glass() {}\nfn main() {}\n")
        );
        assert_eq!(
            compose_from(MODULES, "main", &without).as_deref(),
            Ok("fn air() {}\nfn main() {}\n")
        );
    }

    #[test]
    fn a_cycle_is_an_error_that_names_it() {
        const MODULES: &[(&str, &str)] = &[
            ("main", "#import a\n"),
            ("a", "#import b\n"),
            ("b", "#import c\n"),
            ("c", "#import a\n"),
            ("self", "#import self\n"),
        ];
        let error = compose_from(MODULES, "main", &ShaderFeatures::ALL).unwrap_err();
        assert_eq!(
            error,
            ComposeError::ImportCycle {
                cycle: ["a", "b", "c", "a"].map(String::from).to_vec()
            }
        );
        assert_eq!(
            error.to_string(),
            "shader modules import each other: a -> b -> c -> a"
        );
        assert_eq!(
            compose_from(MODULES, "self", &ShaderFeatures::ALL),
            Err(ComposeError::ImportCycle {
                cycle: vec!["self".into(), "self".into()]
            })
        );
    }

    #[test]
    fn a_missing_module_or_a_malformed_import_is_an_error() {
        const MODULES: &[(&str, &str)] = &[
            ("main", "fn main() {}\n#import nowhere\n"),
            ("two", "\n#import a b\n"),
            ("bare", "#import\n"),
            ("glued", "#importa\n"),
            ("directive", "#import main\n//#if GLITTER\n"),
        ];
        let error = compose_from(MODULES, "main", &ShaderFeatures::ALL).unwrap_err();
        assert_eq!(
            error.to_string(),
            "shader module `nowhere` does not exist (imported by `main`)"
        );
        for (module, line) in [("two", 2), ("bare", 1), ("glued", 1)] {
            assert_eq!(
                compose_from(MODULES, module, &ShaderFeatures::ALL),
                Err(ComposeError::MalformedImport {
                    module: module.into(),
                    line
                })
            );
        }
        assert!(matches!(
            compose_from(MODULES, "directive", &ShaderFeatures::ALL),
            Err(ComposeError::Directive { module, .. }) if module == "directive"
        ));
        assert!(matches!(
            compose_from(MODULES, "elsewhere", &ShaderFeatures::ALL),
            Err(ComposeError::MissingModule { importer: None, .. })
        ));
    }

    #[test]
    fn imports_are_listed_as_specialised() {
        let source = "#import a\n//#if PBR\n#import b\n//#endif\nfn f() {}\n";
        let no_pbr = ShaderFeatures {
            pbr: false,
            ..ShaderFeatures::ALL
        };
        assert_eq!(
            imports_of("m", source, &ShaderFeatures::ALL),
            Ok(vec!["a".into(), "b".into()])
        );
        assert_eq!(imports_of("m", source, &no_pbr), Ok(vec!["a".into()]));
    }
}
