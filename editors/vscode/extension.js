// The whitted extension: highlighting comes from syntaxes/whitted.tmLanguage.json (declared
// in package.json); this file starts `whitted lsp` for .scene files with vscode-languageclient.
const vscode = require("vscode");
const { LanguageClient } = require("vscode-languageclient/node");

let client;

exports.activate = function (context) {
  const command = vscode.workspace.getConfiguration("whitted").get("command") || "whitted";
  client = new LanguageClient(
    "whitted",
    "whitted",
    { command, args: ["lsp"] },
    { documentSelector: [{ scheme: "file", language: "whitted" }] }
  );
  client.start();
  context.subscriptions.push({ dispose: () => client && client.stop() });
};

exports.deactivate = () => (client ? client.stop() : undefined);
