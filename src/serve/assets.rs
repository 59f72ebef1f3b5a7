//! What the server embeds (docs/serve.md §The page): the page (HTML, JavaScript and CSS written by hand, no
//! toolchain, no outside library) and the shipped recipes it can start from (`fixtures/recipes/`, every one
//! that names no table file), so that the binary serves them with nothing beside it.

/// The page.
pub(crate) const INDEX_HTML: &str = include_str!("page/index.html");
pub(crate) const APP_JS: &str = include_str!("page/app.js");
pub(crate) const APP_CSS: &str = include_str!("page/app.css");

/// The shipped recipes the page starts from: (name, the file's text), the first the page's default.
pub(crate) const FIXTURES: &[(&str, &str)] = &[
    ("cerulean-blue-c", include_str!("../../fixtures/recipes/cerulean-blue-c.json")),
    ("semigloss-white", include_str!("../../fixtures/recipes/semigloss-white.json")),
    ("black-glass", include_str!("../../fixtures/recipes/black-glass.json")),
    ("white-pearl", include_str!("../../fixtures/recipes/white-pearl.json")),
    ("silver-metallic", include_str!("../../fixtures/recipes/silver-metallic.json")),
    ("bench-b1-lambert", include_str!("../../fixtures/recipes/bench-b1-lambert.json")),
    ("bench-b2-beckmann-0.1", include_str!("../../fixtures/recipes/bench-b2-beckmann-0.1.json")),
    ("bench-b3-beckmann-1e-4", include_str!("../../fixtures/recipes/bench-b3-beckmann-1e-4.json")),
    ("bench-b4-ggx-0.3", include_str!("../../fixtures/recipes/bench-b4-ggx-0.3.json")),
    ("blinn-phong", include_str!("../../fixtures/recipes/blinn-phong.json")),
    ("blue-metallic-spectral", include_str!("../../fixtures/recipes/blue-metallic-spectral.json")),
    ("cerulean-blue-a", include_str!("../../fixtures/recipes/cerulean-blue-a.json")),
    ("cerulean-blue-b-literal", include_str!("../../fixtures/recipes/cerulean-blue-b-literal.json")),
    ("cerulean-blue-b", include_str!("../../fixtures/recipes/cerulean-blue-b.json")),
    ("cerulean-blue-c-literal", include_str!("../../fixtures/recipes/cerulean-blue-c-literal.json")),
    ("clear-coat-haze", include_str!("../../fixtures/recipes/clear-coat-haze.json")),
    ("conductor-example", include_str!("../../fixtures/recipes/conductor-example.json")),
    ("conductor-rgb-example", include_str!("../../fixtures/recipes/conductor-rgb-example.json")),
    ("cook-torrance-lobes", include_str!("../../fixtures/recipes/cook-torrance-lobes.json")),
    ("glass-n1.5", include_str!("../../fixtures/recipes/glass-n1.5.json")),
    ("grey-lambert", include_str!("../../fixtures/recipes/grey-lambert.json")),
    ("phong", include_str!("../../fixtures/recipes/phong.json")),
    ("rgb-lambert", include_str!("../../fixtures/recipes/rgb-lambert.json")),
    ("rough-conductor-ggx", include_str!("../../fixtures/recipes/rough-conductor-ggx.json")),
    ("rough-dielectric-beckmann", include_str!("../../fixtures/recipes/rough-dielectric-beckmann.json")),
    ("rough-dielectric-ggx-vcavity", include_str!("../../fixtures/recipes/rough-dielectric-ggx-vcavity.json")),
    ("solid-black", include_str!("../../fixtures/recipes/solid-black.json")),
    ("solid-white", include_str!("../../fixtures/recipes/solid-white.json")),
    ("ward", include_str!("../../fixtures/recipes/ward.json")),
    ("white-pearl-spectral", include_str!("../../fixtures/recipes/white-pearl-spectral.json")),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_embedded_recipe_is_valid() {
        for (name, text) in FIXTURES {
            crate::recipe::parse_str(text, name).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
}
