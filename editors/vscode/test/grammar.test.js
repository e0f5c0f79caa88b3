// The TextMate grammar (syntaxes/whitted.tmLanguage.json) under a real TextMate engine: the
// one VS Code uses (vscode-textmate, with the Oniguruma regular expressions compiled to wasm).
// Run with plain `node editors/vscode/test/grammar.test.js` after `npm ci` in editors/vscode;
// `cargo xtask ci` runs it. It tokenizes every scene in scenes/ and checks, in all of them,
// that every character outside whitespace gets a scope, that every reserved word outside
// comments and strings is a keyword (or a constant for `true`, `false`, `open`), that every
// number is a number, and that no comment or string runs past the end of the file; then it
// checks chosen lines token by token.
"use strict";

const fs = require("fs");
const path = require("path");
const assert = require("assert");

const here = __dirname;
const root = path.resolve(here, "../../..");
const modules = path.resolve(here, "../node_modules");
let vsctm, oniguruma;
try {
  vsctm = require(path.join(modules, "vscode-textmate"));
  oniguruma = require(path.join(modules, "vscode-oniguruma"));
} catch (error) {
  console.error(`grammar test: run \`npm ci\` in editors/vscode first (${error.message})`);
  process.exit(1);
}

const KEYWORDS = new Set(
  "import const let fn for in if else return while step settings camera light material about".split(" "),
);
const NUMBER = /^(\d+(\.\d+)?|\.\d+)([eE][+-]?\d+)?$/;

async function loadGrammar() {
  const wasm = fs.readFileSync(path.join(modules, "vscode-oniguruma/release/onig.wasm")).buffer;
  await oniguruma.loadWASM(wasm);
  const grammarPath = path.resolve(here, "../syntaxes/whitted.tmLanguage.json");
  const registry = new vsctm.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (patterns) => new oniguruma.OnigScanner(patterns),
      createOnigString: (text) => new oniguruma.OnigString(text),
    }),
    loadGrammar: async (scopeName) =>
      scopeName === "source.whitted"
        ? vsctm.parseRawGrammar(fs.readFileSync(grammarPath, "utf8"), grammarPath)
        : null,
  });
  return registry.loadGrammar("source.whitted");
}

/** Every line of `text` as a list of tokens `{ text, scopes }`, and the state at the end. */
function tokenize(grammar, text) {
  let stack = vsctm.INITIAL;
  const lines = text.split(/\r?\n/).map((line) => {
    const result = grammar.tokenizeLine(line, stack);
    stack = result.ruleStack;
    return result.tokens.map((t) => ({
      text: line.slice(t.startIndex, t.endIndex),
      start: t.startIndex,
      scopes: t.scopes,
    }));
  });
  return { lines, endDepth: stack.depth };
}

function scenes(dir) {
  return fs.readdirSync(dir, { withFileTypes: true }).flatMap((entry) => {
    const full = path.join(dir, entry.name);
    if (entry.isDirectory()) return scenes(full);
    return entry.name.endsWith(".scene") ? [full] : [];
  });
}

const has = (token, prefix) => token.scopes.some((s) => s === prefix || s.startsWith(prefix + "."));
const inCommentOrString = (token) => has(token, "comment") || has(token, "string");

/** Generic checks that hold on any scene. */
function checkScene(label, result, firstLine = 1) {
  const where = (n) => `${label}:${firstLine + n}`;
  assert.strictEqual(result.endDepth, 1, `${where(result.lines.length - 1)}: a comment or string runs past the end`);
  let keywords = 0;
  let numbers = 0;
  result.lines.forEach((tokens, n) => {
    for (const token of tokens) {
      const word = token.text.trim();
      if (word === "") continue;
      assert.ok(token.scopes.length > 1, `${where(n)}: \`${token.text}\` has no scope`);
      if (inCommentOrString(token)) continue;
      if (KEYWORDS.has(word)) {
        assert.ok(has(token, "keyword.control"), `${where(n)}: keyword \`${word}\` is ${token.scopes}`);
        keywords++;
      }
      if (word === "true" || word === "false" || word === "open") {
        assert.ok(has(token, "constant.language"), `${where(n)}: \`${word}\` is ${token.scopes}`);
      }
      if (NUMBER.test(word)) {
        assert.ok(has(token, "constant.numeric"), `${where(n)}: number \`${word}\` is ${token.scopes}`);
        numbers++;
      }
    }
  });
  return { keywords, numbers };
}

/**
 * On line `line` (from 1) of `scene`, the `nth` (from 0) occurrence of `text` must be one
 * token, or lie inside one, that has a scope starting with `scope`.
 */
function expectScope(tokenized, scene, line, text, scope, nth = 0) {
  const tokens = tokenized[scene].lines[line - 1];
  assert.ok(tokens, `${scene} has no line ${line}`);
  const lineText = tokens.map((t) => t.text).join("");
  let at = -1;
  for (let i = 0; i <= nth; i++) {
    at = lineText.indexOf(text, at + 1);
    assert.ok(at >= 0, `${scene}:${line}: \`${text}\` not found in \`${lineText}\``);
  }
  const covering = tokens.filter((t) => t.start < at + text.length && t.start + t.text.length > at);
  for (const token of covering) {
    assert.ok(
      has(token, scope),
      `${scene}:${line}: \`${text}\` should be ${scope}, but \`${token.text}\` is ${token.scopes.join(" ")}`,
    );
  }
}

async function main() {
  const grammar = await loadGrammar();
  const files = scenes(path.join(root, "scenes"));
  assert.ok(files.length >= 30, `only ${files.length} scenes found under scenes/`);
  const tokenized = {};
  let keywords = 0;
  let numbers = 0;
  for (const file of files) {
    const result = tokenize(grammar, fs.readFileSync(file, "utf8"));
    const counts = checkScene(path.relative(root, file), result);
    keywords += counts.keywords;
    numbers += counts.numbers;
    tokenized[path.relative(path.join(root, "scenes"), file).split(path.sep).join("/")] = result;
  }
  // The scene examples of docs/language.md (```scene fences), with the same checks.
  const docs = fs.readFileSync(path.join(root, "docs/language.md"), "utf8").split("\n");
  let examples = 0;
  for (let i = 0; i < docs.length; i++) {
    if (!/^```scene\b/.test(docs[i])) continue;
    const start = i + 1;
    while (i + 1 < docs.length && !docs[i + 1].startsWith("```")) i++;
    const counts = checkScene("docs/language.md", tokenize(grammar, docs.slice(start, i + 1).join("\n")), start + 1);
    keywords += counts.keywords;
    numbers += counts.numbers;
    examples++;
    i++;
  }
  assert.ok(examples >= 25, `only ${examples} scene examples found in docs/language.md`);
  assert.ok(keywords > 100 && numbers > 1000, `too few keywords (${keywords}) or numbers (${numbers}) seen`);

  const e = (...args) => expectScope(tokenized, ...args);
  // Comments, line and block.
  e("glass.scene", 1, "// Glass with", "comment.line.double-slash");
  e("glass.scene", 1, "Fresnel: left", "comment.line.double-slash");
  // Keywords, block kinds, properties, numbers, strings.
  e("glass.scene", 5, "settings", "keyword.control");
  e("glass.scene", 5, "width", "variable.other.property");
  e("glass.scene", 5, "640", "constant.numeric");
  e("glass.scene", 5, "rgb", "support.function.builtin");
  e("glass.scene", 5, "0.3", "constant.numeric");
  e("glass.scene", 6, "camera", "keyword.control");
  e("glass.scene", 6, "perspective", "support.type");
  e("glass.scene", 6, "look_at", "variable.other.property");
  e("glass.scene", 6, "-", "keyword.operator.arithmetic");
  e("glass.scene", 6, "7", "constant.numeric");
  e("glass.scene", 6, "<0, 1.5, -7>", "meta.vector");
  e("glass.scene", 7, "light", "keyword.control");
  e("glass.scene", 7, "point", "support.type");
  e("glass.scene", 9, "material", "keyword.control");
  e("glass.scene", 9, "plain_glass", "entity.name.type.material");
  e("glass.scene", 13, "fresnel_glass", "entity.name.type.material");
  e("glass.scene", 13, "plain_glass", "entity.other.inherited-class");
  e("glass.scene", 13, "schlick", "constant.language");
  e("glass.scene", 14, "plane", "support.type");
  e("glass.scene", 15, "sphere", "support.type");
  e("glass.scene", 15, '"fixed glass"', "string.quoted.double");
  // Functions, loops, calls, string holes, imports.
  e("provenance/lib.scene", 1, "A library", "comment.line.double-slash");
  e("provenance/lib.scene", 5, "fn", "keyword.control");
  e("provenance/lib.scene", 5, "ring", "entity.name.function");
  e("provenance/lib.scene", 5, "n", "variable.parameter", 2);
  e("provenance/lib.scene", 6, "for", "keyword.control");
  e("provenance/lib.scene", 6, "in", "keyword.control");
  e("provenance/lib.scene", 6, "..", "keyword.operator.range");
  e("provenance/lib.scene", 7, '"bead {i}"', "string.quoted.double");
  e("provenance/lib.scene", 7, "{i}", "meta.interpolation");
  e("provenance/lib.scene", 8, "cos", "support.function.builtin");
  e("provenance/lib.scene", 8, "360", "constant.numeric");
  e("provenance/main.scene", 5, "import", "keyword.control");
  e("provenance/main.scene", 5, '"lib.scene"', "string.quoted.double");
  e("provenance/main.scene", 7, "#101018", "constant.other.color");
  e("provenance/main.scene", 9, "white", "support.constant");
  e("provenance/main.scene", 12, "ring", "entity.name.function");
  e("provenance/main.scene", 12, "12", "constant.numeric");
  e("provenance/main.scene", 12, "translate", "variable.other.property");
  e("lang-pool-table.scene", 18, "const", "keyword.control");
  e("lang-pool-table.scene", 18, "BALL", "variable.other.constant");
  e("lang-pool-table.scene", 18, "0.25", "constant.numeric");
  e("lang-pool-table.scene", 18, "// radius", "comment.line.double-slash");
  e("lang-pool-table.scene", 26, "if", "keyword.control");
  e("lang-pool-table.scene", 26, "==", "keyword.operator.comparison");
  e("lang-pool-table.scene", 26, "return", "keyword.control");

  // Constructs that no scene has: block comments, escapes, words, `else`, `about`, `open`.
  const sample = [
    "/* a block comment",
    "   over two lines */ let x = 1e-4; // after",
    'sphere "a \\"quoted\\" {{name}}" { radius .5 }',
    "settings { shadows filtered filter box sampling jittered }",
    "if x < 2 && !false { cylinder { open rotate 30 about <0, 1, 0> } } else { disk { } }",
  ].join("\n");
  tokenized["sample"] = tokenize(grammar, sample);
  checkScene("sample", tokenized["sample"]);
  e("sample", 1, "a block comment", "comment.block");
  e("sample", 2, "over two lines */", "comment.block");
  e("sample", 2, "let", "keyword.control");
  e("sample", 2, "1e-4", "constant.numeric");
  e("sample", 2, "// after", "comment.line");
  e("sample", 3, '\\"', "constant.character.escape");
  e("sample", 3, "{{", "constant.character.escape");
  e("sample", 3, ".5", "constant.numeric");
  e("sample", 4, "filtered", "constant.language");
  e("sample", 4, "box", "constant.language");
  e("sample", 4, "jittered", "constant.language");
  e("sample", 5, "<", "keyword.operator.comparison");
  e("sample", 5, "&&", "keyword.operator.logical");
  e("sample", 5, "false", "constant.language.boolean");
  e("sample", 5, "cylinder", "support.type");
  e("sample", 5, "open", "constant.language");
  e("sample", 5, "about", "keyword.control");
  e("sample", 5, "else", "keyword.control");
  e("sample", 5, "disk", "support.type");

  console.log(
    `grammar test: ${files.length} scenes and ${examples} docs examples tokenized (${keywords} keywords, ${numbers} numbers), chosen lines ok`,
  );
}

main().catch((error) => {
  console.error(`grammar test failed: ${error.message}`);
  process.exit(1);
});
