; Highlighting for whitted scenes, in Neovim's capture names (nvim-treesitter's set, which
; Zed and the tree-sitter CLI also read). Ordered as Neovim wants: general patterns first, as
; a later pattern wins over an earlier one for the same node.

(identifier) @variable

; Comments, strings, numbers
(line_comment) @comment
(block_comment) @comment
(string) @string
(escape_sequence) @string.escape
(interpolation) @string.special
(number) @number
(hex_color) @constant
(boolean) @boolean

; Keywords
[
  "import"
] @keyword.import

[
  "if"
  "else"
] @keyword.conditional

[
  "for"
  "in"
  "step"
  "while"
] @keyword.repeat

"return" @keyword.return

"fn" @keyword.function

[
  "let"
  "const"
  "settings"
  "camera"
  "light"
  "material"
  "about"
] @keyword

(flag) @constant.builtin

; Definitions
(function_definition
  name: (identifier) @function)
(parameters
  (identifier) @variable.parameter)
(let_declaration
  name: (identifier) @variable)
(const_declaration
  name: (identifier) @constant)
(for_statement
  variable: (identifier) @variable)
(material_definition
  name: (identifier) @type.definition)
(material_definition
  base: (identifier) @type)
(material_property
  base: (identifier) @type)
(material_literal
  base: (identifier) @type)

; Kinds of object, light and camera
(object
  kind: (identifier) @type.builtin)
(light_statement
  kind: (identifier) @type.builtin)
(camera_statement
  kind: (identifier) @type.builtin)

; Properties, and the words some of them take
(property
  name: (identifier) @property)
(property
  value: (identifier) @constant.builtin
  (#any-of? @constant.builtin
    "opaque" "filtered" "none" "off" "schlick" "exact" "phong" "blinn" "jittered" "grid"
    "random" "inverted" "uninverted" "centre" "corner" "box" "tent" "gaussian"))

; Calls
(call
  function: (identifier) @function.call)
(call
  function: (identifier) @function.builtin
  (#any-of? @function.builtin
    "sqrt" "pow" "exp" "log" "sin" "cos" "tan" "asin" "acos" "atan" "atan2" "radians"
    "degrees" "abs" "min" "max" "clamp" "floor" "ceil" "round" "dot" "cross" "length"
    "normalize" "mix" "rgb" "srgb" "checker" "stripes" "marble" "wood" "turbulence" "len"
    "rand"))

; Names the language predefines
((identifier) @constant.builtin
  (#any-of? @constant.builtin
    "white" "black" "gray" "grey" "red" "green" "blue" "yellow" "cyan" "magenta" "pi"))

(field_expression
  field: (identifier) @variable.member)

; Operators and punctuation
[
  "="
  "+"
  "-"
  "*"
  "/"
  "%"
  "=="
  "!="
  "<="
  ">="
  "&&"
  "||"
  "!"
  ".."
  "..="
] @operator

(binary_expression
  operator: [
    "<"
    ">"
  ] @operator)

(vector
  [
    "<"
    ">"
  ] @punctuation.bracket)

[
  "{"
  "}"
  "("
  ")"
  "["
  "]"
] @punctuation.bracket

[
  ","
  ";"
  ":"
  "."
] @punctuation.delimiter
