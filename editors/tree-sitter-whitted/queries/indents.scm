; Indentation, in nvim-treesitter's capture names: one level inside braces, brackets and
; parentheses; the closing delimiter goes back out. (Helix reads `@indent`/`@outdent`
; instead; docs/editors.md has its variant.)
[
  (block)
  (array)
  (arguments)
  (parameters)
  (parenthesized_expression)
] @indent.begin

[
  "}"
  "]"
  ")"
] @indent.branch @indent.end

(block_comment) @indent.auto
