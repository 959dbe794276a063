"""The simple commands of a bash script: enough of bash's grammar to find the programs it runs.

``simple_commands(text)`` yields ``(line, words)`` for each simple command, with quotes and
leading reserved words (``then``, ``do``, ``!``, ...) removed,
including the commands inside ``$(...)``, backticks and ``"...$(...)..."``. Comments,
here-document bodies, ``case`` patterns, ``for`` word lists and arithmetic ``((...))`` are
skipped.
"""

from __future__ import annotations

import re

HEREDOC = re.compile(r"(?<!<)<<(?!<)-?\s*(['\"]?)([A-Za-z_][A-Za-z0-9_]*)\1")
# Reserved words that may come before a command ("then make", "do ls", "! grep").
RESERVED = {"if", "then", "else", "elif", "fi", "do", "done", "while", "until", "esac", "time",
            "!", "{", "}"}
OPERATORS = ("&&", "||", ";;", ";", "|", "&", "\n")


class _Lexer:
    def __init__(self, text):
        self.text = _without_heredoc_bodies(text)
        self.pos = 0
        self.line = 1
        self.commands = []

    def peek(self, n=1):
        return self.text[self.pos:self.pos + n]

    def advance(self, n=1):
        chunk = self.text[self.pos:self.pos + n]
        self.line += chunk.count("\n")
        self.pos += n
        return chunk

    def run(self):
        self.command_list(closing=None)
        return self.commands

    def command_list(self, closing):
        """Reads commands until `closing` (")" or "`") or the end; returns at the closing."""
        words, word, start = [], None, self.line
        depth = 0  # open "(" subshells within this list
        cases = 0  # open "case ... esac" within this list
        pattern = False  # at a case pattern ("a|b)"), which is no command

        def finish():
            nonlocal words, word, start, cases, pattern
            if word is not None:
                words.append(word)
            while words and words[0] in RESERVED:
                words = words[1:]
            if words[:1] == ["case"] and words[-1] == "in":
                cases += 1
                pattern = True
            elif words and words[0] not in ("for", "select"):
                self.commands.append((start, words))
            words, word, start = [], None, self.line

        while self.pos < len(self.text):
            if pattern:
                pattern, closed = self.case_pattern()
                cases -= closed
                start = self.line
                continue
            c = self.peek()
            if closing and c == closing and not (closing == ")" and depth):
                finish()
                self.advance()
                return
            if c == "\\" and self.peek(2) == "\\\n":
                self.advance(2)
            elif c == "\\":
                self.advance()
                word = (word or "") + self.advance()
            elif c == "#" and word is None:
                while self.pos < len(self.text) and self.peek() != "\n":
                    self.advance()
            elif c == "'":
                self.advance()
                end = self.text.find("'", self.pos)
                end = len(self.text) if end < 0 else end
                word = (word or "") + self.advance(end - self.pos)
                self.advance()
            elif c == '"':
                word = (word or "") + self.double_quoted()
            elif self.peek(3) == "$((" or (self.peek(2) == "((" and word is None):
                self.skip_arithmetic()
                word = (word or "") + "0"
            elif self.peek(2) == "$(":
                self.advance(2)
                self.command_list(closing=")")
                word = (word or "") + "$"
            elif self.peek(2) == "${":
                word = (word or "") + self.parameter()
            elif c == "`":
                self.advance()
                self.command_list(closing="`")
                word = (word or "") + "$"
            elif c == "(" and word is None:
                self.advance()
                finish()
                depth += 1
            elif c == "(":
                word += self.advance()  # e.g. an array assignment a=(...): kept as data
            elif c == ")":
                self.advance()
                if depth:
                    depth -= 1
                    finish()
                else:
                    # An unmatched ")" closes a case pattern: those words were no command.
                    words, word, start = [], None, self.line
            elif c == "&" and ((word or "").endswith((">", "<")) or self.peek(2) == "&>"):
                word = (word or "") + self.advance()  # a redirection: >&2, &>file
            elif any(self.text.startswith(op, self.pos) for op in OPERATORS):
                op = next(op for op in OPERATORS if self.text.startswith(op, self.pos))
                finish()
                self.advance(len(op))
                start = self.line
                pattern = pattern or (op == ";;" and cases > 0)
            elif c in " \t":
                if word is not None:
                    words.append(word)
                    word = None
                if len(words) == 3 and words[0] == "case" and words[2] == "in":
                    finish()
                self.advance()
            else:
                word = (word or "") + self.advance()
        finish()

    def case_pattern(self):
        """Skips one case pattern up to its ")"; returns (False, 1) at "esac", else (False, 0)."""
        while self.pos < len(self.text) and self.peek() in " \t\n":
            self.advance()
        if re.match(r"esac\b", self.text[self.pos:]):
            self.advance(4)
            return False, 1
        while self.pos < len(self.text) and self.peek() != ")":
            if self.peek() in "'\"":
                quote = self.advance()
                while self.pos < len(self.text) and self.peek() != quote:
                    self.advance()
            self.advance()
        self.advance()
        return False, 0

    def double_quoted(self):
        self.advance()
        text = ""
        while self.pos < len(self.text) and self.peek() != '"':
            if self.peek() == "\\":
                self.advance()
                text += self.advance()
            elif self.peek(3) == "$((":
                self.skip_arithmetic()
                text += "0"
            elif self.peek(2) == "$(":
                self.advance(2)
                self.command_list(closing=")")
                text += "$"
            elif self.peek() == "`":
                self.advance()
                self.command_list(closing="`")
                text += "$"
            else:
                text += self.advance()
        self.advance()
        return text

    def parameter(self):
        """A ${...} expansion, kept as data (its words are no command)."""
        depth, text = 0, ""
        while self.pos < len(self.text):
            c = self.advance()
            text += c
            if c == "{":
                depth += 1
            elif c == "}":
                depth -= 1
                if depth == 0:
                    break
        return text

    def skip_arithmetic(self):
        depth = 0
        while self.pos < len(self.text):
            c = self.advance()
            if c == "(":
                depth += 1
            elif c == ")":
                depth -= 1
                if depth == 0:
                    return


def _without_heredoc_bodies(text):
    out, lines, i = [], text.split("\n"), 0
    while i < len(lines):
        out.append(lines[i])
        delimiters = [m.group(2) for m in HEREDOC.finditer(lines[i])]
        i += 1
        for delimiter in delimiters:
            while i < len(lines) and lines[i].strip() != delimiter:
                out.append("")  # keep the line numbers
                i += 1
            if i < len(lines):
                out.append("")
                i += 1
    return "\n".join(out)


def simple_commands(text):
    """(line, words) of each simple command of a bash script, quotes removed."""
    return _Lexer(text).run()
