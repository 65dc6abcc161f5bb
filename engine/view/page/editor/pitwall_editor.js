// The code editor of the page (issue 39, docs/view.md): CodeMirror 6 from the pinned npm packages
// (package.json), bundled at build time by esbuild into web/vendor/pitwall-editor.js (CMakeLists.txt)
// — no CDN, nothing copied into the repository. It sets window.PitwallEditor:
//
//   const editor = PitwallEditor.create(parent, {
//     doc: "return …",                  // the text to edit
//     completions: { "car:": [{ label: "setSpeed", type: "method", detail: "(speed, accel)",
//                               info: "…" }], … },  // after "NAME:" or "NAME.", by that prefix;
//                                                   // "" for names typed alone
//     onChange: (text) => { … },        // each change of the text
//   });
//   editor.text()                       // the text now
//   editor.setText(text)
//   editor.showErrors([{ line: 3, message: "…" }])  // marked at their lines (1-based); [] clears
// Hovering a name the completions know (car:setSpeed, drivers.cap, …) shows its signature and doc.
//   editor.view                         // the EditorView
import { basicSetup, EditorView } from "codemirror";
import { hoverTooltip } from "@codemirror/view";
import { EditorState } from "@codemirror/state";
import { StreamLanguage } from "@codemirror/language";
import { lua } from "@codemirror/legacy-modes/mode/lua";
import { autocompletion } from "@codemirror/autocomplete";
import { setDiagnostics } from "@codemirror/lint";

// Completions for the word under the cursor: after "NAME:" or "NAME." the entries of that prefix,
// else those of "".
function completionSource(completions) {
  return (context) => {
    const member = context.matchBefore(/[A-Za-z_][A-Za-z0-9_]*[:.][A-Za-z0-9_]*/);
    if (member) {
      const cut = Math.max(member.text.lastIndexOf(":"), member.text.lastIndexOf("."));
      const prefix = member.text.slice(0, cut + 1);
      const options = completions[prefix];
      if (options) return { from: member.from + cut + 1, options, validFor: /^[A-Za-z0-9_]*$/ };
    }
    const word = context.matchBefore(/[A-Za-z_][A-Za-z0-9_]*/);
    if (!word && !context.explicit) return null;
    const options = completions[""];
    if (!options) return null;
    return { from: word ? word.from : context.pos, options, validFor: /^[A-Za-z0-9_]*$/ };
  };
}

// The doc of the name under the pointer: "NAME:word" or "NAME.word" by that prefix's entries, a
// name typed alone by those of "".
function hoverDocs(completions) {
  const name = /[A-Za-z0-9_]/;
  return hoverTooltip((view, pos) => {
    const line = view.state.doc.lineAt(pos);
    const text = line.text;
    let start = pos - line.from, end = start;
    while (start > 0 && name.test(text[start - 1])) start--;
    while (end < text.length && name.test(text[end])) end++;
    if (start === end) return null;
    const word = text.slice(start, end);
    let prefix = "";
    if (start > 0 && (text[start - 1] === ":" || text[start - 1] === ".")) {
      let p = start - 1;
      while (p > 0 && name.test(text[p - 1])) p--;
      prefix = text.slice(p, start);
    }
    const entry = (completions[prefix] || []).find((c) => c.label === word);
    if (!entry) return null;
    return {
      pos: line.from + start,
      end: line.from + end,
      above: true,
      create() {
        const dom = document.createElement("div");
        dom.className = "cm-pitwall-doc";
        const signature = document.createElement("code");
        signature.textContent = prefix + entry.label + (entry.detail || "");
        const info = document.createElement("div");
        info.textContent = entry.info || "";
        dom.append(signature, info);
        return { dom };
      },
    };
  });
}

function create(parent, options = {}) {
  const completions = options.completions || {};
  const onChange = options.onChange;
  const view = new EditorView({
    parent,
    state: EditorState.create({
      doc: options.doc || "",
      extensions: [
        basicSetup,
        StreamLanguage.define(lua),
        autocompletion({ override: [completionSource(completions)] }),
        hoverDocs(completions),
        EditorView.updateListener.of((update) => {
          if (update.docChanged && onChange) onChange(update.state.doc.toString());
        }),
      ],
    }),
  });
  return {
    view,
    text: () => view.state.doc.toString(),
    setText(text) {
      view.dispatch({ changes: { from: 0, to: view.state.doc.length, insert: text } });
    },
    showErrors(errors) {
      const doc = view.state.doc;
      const diagnostics = (errors || []).map((e) => {
        const line = doc.line(Math.min(Math.max(1, e.line | 0), doc.lines));
        return { from: line.from, to: line.to, severity: "error", message: String(e.message) };
      });
      view.dispatch(setDiagnostics(view.state, diagnostics));
    },
  };
}

window.PitwallEditor = { create };
