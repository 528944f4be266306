"""mbjax's implementation. Nothing here is public: the names users import are re-exported by
`mbjax` and its namespaces (`mbjax.rigid`, `mbjax.loops`, ...), which list them."""
