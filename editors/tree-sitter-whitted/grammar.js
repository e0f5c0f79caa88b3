/**
 * Tree-sitter grammar for the whitted scene language, written from grammar/scene.pest (the
 * one authoritative grammar: where the two disagree, scene.pest is right and this file is the
 * bug). It is for editors (highlighting, folding, indentation), so it is a little more
 * permissive than pest in places that do not matter for that (whitespace inside `a.x`), and
 * exactly as strict where a reader would see a difference: keywords are reserved, a call's
 * `(` follows its name without a space (`f(2)` is a call, `scale (2)` a property), and a bare
 * `>` closes a vector, so only arithmetic may appear inside `<x, y, z>`.
 *
 * editors/tree-sitter-whitted/tests/ (cargo test -p tree-sitter-whitted) parses every scene in
 * scenes/ and every scene example of docs/language.md with this grammar.
 */

// From loosest to tightest, as in docs/language.md (crates/lang/src/parser.rs, `precedence`).
const PREC = {
  or: 1,
  and: 2,
  compare: 3,
  add: 4,
  multiply: 5,
  postfix: 7,
};

const commaSep = (rule) => optional(seq(rule, repeat(seq(',', rule)), optional(',')));

module.exports = grammar({
  name: 'whitted',

  extras: ($) => [/[\s\uFEFF]/, $.line_comment, $.block_comment],

  word: ($) => $.identifier,

  // As scene.pest's `keyword`: these are never names, wherever a name could go.
  reserved: {
    global: ($) => [
      'import', 'const', 'let', 'fn', 'for', 'in', 'if', 'else', 'return', 'while', 'step',
      'settings', 'camera', 'light', 'material', 'true', 'false', 'about', 'open',
    ],
  },

  conflicts: ($) => [],

  rules: {
    source_file: ($) => repeat($._item),

    block: ($) => seq('{', repeat($._item), '}'),

    // One rule for every place a statement can go, as in scene.pest's `item`.
    _item: ($) =>
      choice(
        $.import_statement,
        $.const_declaration,
        $.function_definition,
        $.let_declaration,
        $.for_statement,
        $.while_statement,
        $.if_statement,
        $.return_statement,
        $.settings_statement,
        $.camera_statement,
        $.light_statement,
        $.material_definition,
        $.material_property,
        $.call_statement,
        $.assignment_statement,
        $.object,
        $.flag,
        $.property,
      ),

    import_statement: ($) => seq('import', field('path', $.string)),
    const_declaration: ($) =>
      seq('const', field('name', $.identifier), '=', field('value', $._expression), ';'),
    let_declaration: ($) =>
      seq('let', field('name', $.identifier), '=', field('value', $._expression), ';'),
    function_definition: ($) =>
      seq(
        'fn',
        field('name', $.identifier),
        field('parameters', $.parameters),
        field('body', choice($.block, $.expression_body)),
      ),
    expression_body: ($) => seq('=', $._expression, ';'),
    parameters: ($) => seq(choice('(', $._call_open), commaSep($.identifier), ')'),
    for_statement: ($) =>
      seq(
        'for',
        field('variable', $.identifier),
        'in',
        field('start', $._expression),
        field('operator', choice('..', '..=')),
        field('end', $._expression),
        optional(seq('step', field('step', $._expression))),
        field('body', $.block),
      ),
    while_statement: ($) => seq('while', field('condition', $._expression), field('body', $.block)),
    assignment_statement: ($) =>
      seq(field('name', $.identifier), '=', field('value', $._expression), ';'),
    if_statement: ($) =>
      seq(
        'if',
        field('condition', $._expression),
        field('consequence', $.block),
        optional(seq('else', field('alternative', choice($.if_statement, $.block)))),
      ),
    return_statement: ($) => seq('return', $._expression, ';'),
    settings_statement: ($) => seq('settings', field('body', $.block)),
    camera_statement: ($) => seq('camera', field('kind', $.identifier), field('body', $.block)),
    light_statement: ($) =>
      seq('light', field('kind', $.identifier), optional(field('name', $.string)), field('body', $.block)),
    // `material glass { ... }`, `material tinted : glass { ... }`.
    material_definition: ($) =>
      seq(
        'material',
        field('name', $.identifier),
        optional(seq(':', field('base', $.identifier))),
        field('body', $.block),
      ),
    // Inside an object: `material glass`, `material { ... }`, `material : glass { ... }`.
    material_property: ($) => seq('material', choice($._material_body, field('value', $._expression))),
    _material_body: ($) => seq(optional(seq(':', field('base', $.identifier))), field('body', $.block)),
    // `ring(12, 2)` or `ring(12, 2) { translate <0, 1, 0> }`.
    call_statement: ($) => seq($.call, optional(field('body', $.block))),
    // `sphere { ... }`, `sphere "ball" { ... }`: the identifier says which kind of object.
    // pest tries an object before a property, so `box "a" { ... }` is an object, never the
    // property `box` with the value "a" and a block.
    object: ($) =>
      prec(1, seq(field('kind', $.identifier), optional(field('name', $.string)), field('body', $.block))),
    // A property that takes no value.
    flag: ($) => 'open',
    // `radius 1`, `vertices a, b, c`, `rotate 30 about <0, 1, 0>`,
    // `diffuse checker(white, black, 1) { rotate <0, 45, 0> }`.
    property: ($) =>
      prec.right(
        seq(
          field('name', $.identifier),
          field('value', $._expression),
          repeat(seq(',', field('value', $._expression))),
          optional(seq('about', field('axis', $._expression))),
          optional(field('body', $.block)),
        ),
      ),

    // ---------------------------------------------------------------------------------------
    // Expressions

    _expression: ($) => choice($.binary_expression, $.unary_expression, $._postfix),

    binary_expression: ($) => {
      const table = [
        [PREC.or, '||'],
        [PREC.and, '&&'],
        [PREC.compare, choice('==', '!=', '<', '<=', '>', '>=')],
        [PREC.add, choice('+', '-')],
        [PREC.multiply, choice('*', '/', '%')],
      ];
      return choice(
        ...table.map(([p, operator]) =>
          prec.left(
            p,
            seq(field('left', $._expression), field('operator', operator), field('right', $._expression)),
          ),
        ),
      );
    },

    // Inside `<x, y, z>`: arithmetic only, since a bare `>` closes the vector.
    _arith: ($) => choice(alias($.arith_binary_expression, $.binary_expression), $.unary_expression, $._postfix),
    arith_binary_expression: ($) => {
      const table = [
        [PREC.add, choice('+', '-')],
        [PREC.multiply, choice('*', '/', '%')],
      ];
      return choice(
        ...table.map(([p, operator]) =>
          prec.left(p, seq(field('left', $._arith), field('operator', operator), field('right', $._arith))),
        ),
      );
    },

    // Prefix operators apply to one operand with its fields and indices (`-v.x`).
    unary_expression: ($) =>
      seq(field('operator', choice('-', '!')), field('operand', choice($.unary_expression, $._postfix))),

    _postfix: ($) => choice($._primary, $.field_expression, $.index_expression),
    field_expression: ($) => prec(PREC.postfix, seq(field('value', $._postfix), '.', field('field', $.identifier))),
    index_expression: ($) =>
      prec(PREC.postfix, seq(field('value', $._postfix), '[', field('index', $._expression), ']')),

    _primary: ($) =>
      choice(
        $.number,
        $.hex_color,
        $.boolean,
        $.vector,
        $.array,
        $.string,
        $.material_literal,
        $.call,
        $.identifier,
        $.parenthesized_expression,
      ),

    parenthesized_expression: ($) => seq('(', $._expression, ')'),
    array: ($) => seq('[', commaSep($._expression), ']'),
    vector: ($) => seq('<', field('x', $._arith), ',', field('y', $._arith), ',', field('z', $._arith), '>'),
    material_literal: ($) => seq('material', $._material_body),
    // No space between a function's name and its `(`.
    call: ($) => seq(field('function', $.identifier), field('arguments', $.arguments)),
    arguments: ($) => seq($._call_open, commaSep($._expression), ')'),
    _call_open: ($) => alias(token.immediate('('), '('),

    // ---------------------------------------------------------------------------------------
    // Tokens

    boolean: ($) => choice('true', 'false'),
    number: ($) => /(\d+(\.\d+)?|\.\d+)([eE][+-]?\d+)?/,
    hex_color: ($) => /#[0-9a-fA-F]{6}/,
    // `"ball {i}"`: text, escapes (`\"`, `{{`), and holes that name a value.
    string: ($) =>
      seq('"', repeat(choice($.string_content, $.escape_sequence, $.interpolation)), token.immediate('"')),
    string_content: ($) => token.immediate(prec(1, /[^"\\\n{}]+|[{}]/)),
    escape_sequence: ($) => token.immediate(prec(2, choice(/\\./, '{{', '}}'))),
    interpolation: ($) => token.immediate(prec(2, /\{[A-Za-z_][A-Za-z0-9_]*\}/)),
    identifier: ($) => /[A-Za-z_][A-Za-z0-9_]*/,
    line_comment: ($) => token(seq('//', /[^\n]*/)),
    block_comment: ($) => token(seq('/*', /[^*]*\*+([^/*][^*]*\*+)*/, '/')),
  },
});
