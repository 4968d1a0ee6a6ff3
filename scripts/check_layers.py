#!/usr/bin/env python3
# Checks the layering of solver/ and driver/ against the CMake files, which are the only source of
# truth: every target exports solver/ (or the repository root) as its include root, so a wrong-way
# include of a header-only module (coupling/drag_laws.hpp, particles/contact_models.hpp, ...)
# compiles and links although the layering forbids it. This script catches it.
#
# What it reads
#   solver/**/CMakeLists.txt and driver/**/CMakeLists.txt: add_library / add_executable /
#   target_sources (which files a target compiles), target_link_libraries (what it links), and
#   set() / list(APPEND) for source variables. Only targets defined there count (boycott_*);
#   PkgConfig::, fmt::, ... are ignored. A link written $<LINK_LIBRARY:FEATURE,lib> links lib.
#
# Which target a file belongs to
#   1. A file listed in a target's sources belongs to that target (to each, if several list it).
#   2. Any other file (a header) belongs to the target(s) defined by the CMakeLists.txt of its own
#      folder (or, if that folder has none, of the nearest folder above it):
#      a. a folder with one target: that target;
#      b. a folder with several targets (driver/): the target whose sources include the same-named
#         .cpp (foo.hpp -> foo.cpp, also a generated one such as ${...}/schema_files.cpp);
#      c. otherwise (a header-only header there): the folder's library with the fewest
#         dependencies (smallest transitive closure; the first defined one on a tie).
#   A generated header (core/version.hpp) is found as its template, core/version.hpp.in.
#   A .cpp that no target lists is reported as a warning and not checked.
#
# What a target may include
#   Its own headers, those of the targets it links (PUBLIC or PRIVATE), and, transitively, those
#   its linked targets link PUBLIC (or INTERFACE): CMake's usage requirements. A target's PRIVATE
#   links are not visible to those that link it.
#
# Rules (each violation is one output line; exit status 1 if there is any)
#   1. Every `#include "x/y.hpp"` (or <x/y.hpp>) in a .cpp/.hpp under solver/ or driver/ that
#      resolves to a file there (relative to the including file, solver/ or the repository root)
#      must name a header of the file's own target or of one it links (transitively, as above):
#        solver/io/x.cpp:12 includes coupling/kernels.hpp: io does not link coupling
#   2. A direct boycott_* link L of target T is unused when no file of T (its sources and its
#      headers) includes a header of L or of a target that only L brings in (one that T's other
#      direct links do not also bring in); a target that owns no file (a link wrapper) is exempt:
#        solver/io/CMakeLists.txt:3 io links coupling but includes nothing of it ...
#   Includes inside comments and `#if 0` blocks are ignored. Headers that resolve nowhere (system
#   and third-party ones) are ignored; a missing project header (first path component a solver/
#   folder or driver/) is a warning, since the compiler reports it anyway.
#
# Usage: scripts/check_layers.py [--root DIR]   (DIR defaults to the repository holding this script)
# Run by ctest as Style.LayerRulesHold; its own test is tests/style/test_check_layers.py.

import argparse
import os
import re
import sys

SOURCE_EXTS = (".cpp", ".cc", ".cxx", ".c")
HEADER_EXTS = (".hpp", ".hh", ".hxx", ".h")
CODE_ROOTS = ("solver", "driver")

# ---------------------------------------------------------------------------------------------
# CMake


def strip_cmake_comments(text):
    """Replaces `# ...` comments (outside quoted arguments) by spaces, keeping line numbers."""
    out = []
    in_quote = False
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if in_quote:
            out.append(c)
            if c == "\\" and i + 1 < n:
                out.append(text[i + 1])
                i += 2
                continue
            if c == '"':
                in_quote = False
        elif c == '"':
            in_quote = True
            out.append(c)
        elif c == "#":
            m = re.match(r"#\[(=*)\[", text[i:])
            if m:  # bracket comment #[[ ... ]]
                end = text.find("]" + m.group(1) + "]", i + m.end())
                end = n if end < 0 else end + len(m.group(1)) + 2
            else:
                end = text.find("\n", i)
                end = n if end < 0 else end
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
            continue
        else:
            out.append(c)
        i += 1
    return "".join(out)


_ARG_RE = re.compile(r'"((?:\\.|[^"\\])*)"|([^\s()"]+)')


def cmake_commands(path):
    """Yields (name_lower, args, line) for each command invocation of a CMakeLists.txt."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = strip_cmake_comments(f.read())
    pos = 0
    head = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(")
    while True:
        m = head.search(text, pos)
        if not m:
            return
        depth, i, in_quote = 1, m.end(), False
        while i < len(text) and depth:
            c = text[i]
            if in_quote:
                if c == "\\":
                    i += 1
                elif c == '"':
                    in_quote = False
            elif c == '"':
                in_quote = True
            elif c == "(":
                depth += 1
            elif c == ")":
                depth -= 1
            i += 1
        body = text[m.end():i - 1]
        args = [m2.group(1) if m2.group(1) is not None else m2.group(2)
                for m2 in _ARG_RE.finditer(body)]
        yield m.group(1).lower(), args, text.count("\n", 0, m.start()) + 1
        pos = i


class Target:
    def __init__(self, name, kind, cmake_file, line):
        self.name = name
        self.kind = kind  # "library" or "executable"
        self.cmake_file = cmake_file  # repository-relative
        self.folder = os.path.dirname(cmake_file)
        self.line = line
        self.sources = []  # repository-relative paths of files in the tree
        self.generated = []  # basenames of sources outside the tree (build directory)
        self.links = []  # (name, public?, cmake_file, line)

    def short(self):
        return self.name[len("boycott_"):] if self.name.startswith("boycott_") else self.name


_LIB_FLAGS = {"STATIC", "SHARED", "MODULE", "OBJECT", "INTERFACE", "EXCLUDE_FROM_ALL", "GLOBAL"}
_EXE_FLAGS = {"WIN32", "MACOSX_BUNDLE", "EXCLUDE_FROM_ALL"}
_SOURCES_KEYWORDS = {"PRIVATE", "PUBLIC", "INTERFACE", "FILE_SET", "TYPE", "BASE_DIRS", "FILES",
                     "HEADERS", "CXX_MODULES"}


def parse_cmake(root, warnings):
    """Returns {target name: Target} (in definition order) from solver/ and driver/ CMake files."""
    files = []
    for top in CODE_ROOTS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, top)):
            dirnames.sort()
            if "CMakeLists.txt" in filenames:
                files.append(os.path.join(dirpath, "CMakeLists.txt"))
    targets = {}
    pending_links = []
    pending_sources = []
    for path in files:
        rel_cmake = os.path.relpath(path, root)
        folder_abs = os.path.dirname(path)
        variables = {
            "PROJECT_SOURCE_DIR": root,
            "CMAKE_SOURCE_DIR": root,
            "CMAKE_CURRENT_SOURCE_DIR": folder_abs,
            "CMAKE_CURRENT_LIST_DIR": folder_abs,
        }

        def expand(arg, variables=variables):
            for _ in range(10):
                new = re.sub(r"\$\{([A-Za-z0-9_]+)\}",
                             lambda m: variables.get(m.group(1), m.group(0)), arg)
                if new == arg:
                    break
                arg = new
            return [a for a in re.split(r"[;\s]+", arg) if a]

        def add_sources(target, args, folder_abs=folder_abs, expand=expand):
            for arg in args:
                for item in expand(arg):
                    if item.startswith("$<") or not item.lower().endswith(SOURCE_EXTS + HEADER_EXTS):
                        continue
                    if "${" in item:  # a file in the build directory
                        target.generated.append(os.path.basename(item))
                        continue
                    full = os.path.normpath(os.path.join(folder_abs, item))
                    rel = os.path.relpath(full, root)
                    if os.path.isfile(full) and not rel.startswith(".."):
                        target.sources.append(rel)
                    else:
                        target.generated.append(os.path.basename(item))

        for cmd, args, line in cmake_commands(path):
            if cmd == "set" and args:
                vals = []
                for a in args[1:]:
                    if a in ("CACHE", "PARENT_SCOPE"):
                        break
                    vals.append(a)
                variables[args[0]] = ";".join(vals)
            elif cmd == "list" and len(args) >= 2 and args[0] == "APPEND":
                old = variables.get(args[1], "")
                variables[args[1]] = ";".join([old] + args[2:] if old else args[2:])
            elif cmd in ("add_library", "add_executable") and args:
                if "IMPORTED" in args or "ALIAS" in args:
                    continue
                flags = _LIB_FLAGS if cmd == "add_library" else _EXE_FLAGS
                t = Target(args[0], "library" if cmd == "add_library" else "executable", rel_cmake, line)
                if t.name in targets:
                    warnings.append(f"{rel_cmake}:{line} target {t.name} defined twice")
                targets[t.name] = t
                add_sources(t, [a for a in args[1:] if a not in flags])
            elif cmd == "target_sources" and args:
                pending_sources.append((args[0], [a for a in args[1:] if a not in _SOURCES_KEYWORDS],
                                        add_sources))
            elif cmd == "target_link_libraries" and args:
                public = True  # the plain signature propagates like PUBLIC
                for a in args[1:]:
                    if a in ("PUBLIC", "INTERFACE", "LINK_PUBLIC", "LINK_INTERFACE_LIBRARIES"):
                        public = True
                    elif a in ("PRIVATE", "LINK_PRIVATE"):
                        public = False
                    elif a in ("debug", "optimized", "general"):
                        continue
                    else:
                        for item in expand(a):
                            # $<LINK_LIBRARY:WHOLE_ARCHIVE,lib> links lib (with a linker feature).
                            m = re.fullmatch(r"\$<LINK_LIBRARY:[A-Za-z_]+,([A-Za-z0-9_]+)>", item)
                            if m:
                                item = m.group(1)
                            pending_links.append((args[0], item, public, rel_cmake, line))
    for name, args, add in pending_sources:
        if name in targets:
            add(targets[name], args)
    for name, item, public, cmake_file, line in pending_links:
        if name not in targets:
            continue
        if item in targets:
            targets[name].links.append((item, public, cmake_file, line))
        elif item.startswith("boycott_"):
            warnings.append(f"{cmake_file}:{line} {name} links {item}, which no CMakeLists.txt "
                            f"under {'/, '.join(CODE_ROOTS)}/ defines")
    return targets


class Graph:
    def __init__(self, targets):
        self.targets = targets
        self._public = {}

    def public_closure(self, name, _stack=()):
        """Targets whose headers a target that links `name` sees: name and its PUBLIC links, on."""
        if name in self._public:
            return self._public[name]
        seen = {name}
        for dep, public, _, _ in self.targets[name].links:
            if public and dep not in seen and dep not in _stack:
                seen |= self.public_closure(dep, _stack + (name,))
        self._public[name] = seen
        return seen

    def brought_in(self, name, link):
        return self.public_closure(link)

    def visible(self, name):
        """Targets whose headers `name`'s own files may include."""
        seen = {name}
        for dep, _, _, _ in self.targets[name].links:
            seen |= self.public_closure(dep)
        return seen


# ---------------------------------------------------------------------------------------------
# C++


def include_lines(path):
    """Yields (line, quote char, header) for the #include directives of a C++ file, skipping
    comments, string literals and #if 0 blocks."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    # Blank out comments and literals (keeping newlines), so that only real directives remain.
    out = []
    i, n = 0, len(text)
    at_directive = False
    while i < n:
        c = text[i]
        if c == "/" and text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            out.append(" " * (end - i))
            i = end
        elif c == "/" and text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
        elif (c == "R" and text.startswith('R"', i)
              and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_"))):
            m = re.match(r'R"([^()\\\s]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i + m.end())
            end = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
        elif c in "\"'" and not at_directive:
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            end = min(j + 1, n)
            out.append(c + re.sub(r"[^\n]", " ", text[i + 1:end - 1]) + (c if end - 1 > i else ""))
            i = end
        else:
            if c == "\n":
                at_directive = False
            elif c == "#":
                # a string after #include is the header name, not a literal to blank out
                at_directive = re.match(r"#\s*include\b", text[i:i + 40]) is not None
            out.append(c)
            i += 1
    skip_depth = 0
    for lineno, line in enumerate("".join(out).split("\n"), 1):
        m = re.match(r"\s*#\s*(\w+)(.*)", line)
        if not m:
            continue
        word, rest = m.group(1), m.group(2).strip()
        if skip_depth:
            if word in ("if", "ifdef", "ifndef"):
                skip_depth += 1
            elif word == "endif":
                skip_depth -= 1
            elif word in ("else", "elif") and skip_depth == 1:
                skip_depth = 0
            continue
        if word == "if" and rest in ("0", "(0)"):
            skip_depth = 1
        elif word == "include":
            inc = re.match(r'([<"])([^">]+)[">]', rest)
            if inc:
                yield lineno, inc.group(1), inc.group(2)


# ---------------------------------------------------------------------------------------------


class Checker:
    def __init__(self, root):
        self.root = root
        self.warnings = []
        self.targets = parse_cmake(root, self.warnings)
        self.graph = Graph(self.targets)
        self.listed = {}  # file -> [target names]
        for t in self.targets.values():
            for s in t.sources:
                self.listed.setdefault(s, [])
                if t.name not in self.listed[s]:
                    self.listed[s].append(t.name)
        self.folder_targets = {}
        for t in self.targets.values():
            self.folder_targets.setdefault(t.folder, []).append(t.name)
        self.solver_folders = {d for d in os.listdir(os.path.join(root, "solver"))
                               if os.path.isdir(os.path.join(root, "solver", d))} \
            if os.path.isdir(os.path.join(root, "solver")) else set()
        self._owner = {}

    def owners(self, rel):
        """Targets a repository-relative file belongs to (see the rules at the top)."""
        if rel in self._owner:
            return self._owner[rel]
        result = list(self.listed.get(rel, []))
        if not result and not rel.endswith(SOURCE_EXTS):
            folder = os.path.dirname(rel)
            while folder and folder not in self.folder_targets:
                folder = os.path.dirname(folder)
            candidates = self.folder_targets.get(folder, [])
            if len(candidates) == 1:
                result = candidates
            elif candidates:
                name = os.path.basename(rel[:-3] if rel.endswith(".in") else rel)
                stem = os.path.splitext(name)[0]
                same = [c for c in candidates
                        if any(os.path.splitext(os.path.basename(s))[0] == stem and
                               os.path.dirname(s) == os.path.dirname(rel)
                               for s in self.targets[c].sources)]
                if not same:
                    same = [c for c in candidates
                            if any(os.path.splitext(g)[0] == stem for g in self.targets[c].generated)]
                if same:
                    result = same[:1]
                else:
                    libs = [c for c in candidates if self.targets[c].kind == "library"] or candidates
                    result = [min(libs, key=lambda c: len(self.graph.visible(c)))]
        self._owner[rel] = result
        return result

    def resolve(self, including, quote, header):
        """Repository-relative path of the project file an include names, or None."""
        bases = [os.path.dirname(including)] if quote == '"' else []
        bases += ["solver", ""]
        for base in bases:
            rel = os.path.normpath(os.path.join(base, header))
            if rel.startswith(".."):
                continue
            if not rel.startswith(tuple(r + os.sep for r in CODE_ROOTS)):
                continue
            for cand in (rel, rel + ".in"):
                if os.path.isfile(os.path.join(self.root, cand)):
                    return cand
        return None

    def code_files(self):
        files = []
        for top in CODE_ROOTS:
            for dirpath, dirnames, filenames in os.walk(os.path.join(self.root, top)):
                dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
                for fn in sorted(filenames):
                    if fn.endswith(SOURCE_EXTS + HEADER_EXTS):
                        files.append(os.path.relpath(os.path.join(dirpath, fn), self.root))
        return files

    def run(self):
        violations = []
        uses = {name: set() for name in self.targets}  # target -> targets whose headers it includes
        owns_files = set()  # targets that own at least one file
        n_files = n_includes = 0
        for rel in self.code_files():
            mine = self.owners(rel)
            owns_files.update(mine)
            if not mine:
                what = "no target lists it" if rel.endswith(SOURCE_EXTS) else \
                    "no CMakeLists.txt in its folder or above defines a target"
                self.warnings.append(f"{rel}: not checked: {what}")
                continue
            n_files += 1
            for line, quote, header in include_lines(os.path.join(self.root, rel)):
                target_file = self.resolve(rel, quote, header)
                if target_file is None:
                    first = header.split("/")[0]
                    if "/" in header and (first in self.solver_folders or first in CODE_ROOTS):
                        self.warnings.append(f"{rel}:{line} includes {header}, which is not in the tree")
                    continue
                n_includes += 1
                theirs = self.owners(target_file)
                if not theirs:
                    self.warnings.append(f"{rel}:{line} includes {header}, which belongs to no target")
                    continue
                owner = theirs[0]
                for t in mine:
                    if owner != t:
                        uses[t].add(owner)
                    if owner not in self.graph.visible(t):
                        violations.append((rel, line, f"{rel}:{line} includes {header}: "
                                                      f"{self.targets[t].short()} does not link "
                                                      f"{self.targets[owner].short()}"))
        for t in self.targets.values():
            # A target of no files (an INTERFACE library that only passes links on, such as the
            # scenes' whole-archive wrapper) uses its links by definition.
            if t.name not in owns_files:
                continue
            direct = [l[0] for l in t.links]
            for dep, _, cmake_file, line in t.links:
                others = set()
                for other in direct:
                    if other != dep:
                        others |= self.graph.public_closure(other)
                candidates = {dep} | (self.graph.public_closure(dep) - others - {t.name})
                if not (uses[t.name] & candidates):
                    d = self.targets[dep].short()
                    violations.append((cmake_file, line,
                                       f"{cmake_file}:{line} {t.short()} links {d} but no file of "
                                       f"{t.short()} includes a header of {d} (or of a target only "
                                       f"{d} brings in): unused link"))
        return violations, n_files, n_includes


def main(argv=None):
    ap = argparse.ArgumentParser(description="Checks includes in solver/ and driver/ against the "
                                 "CMake target links (see the comment at the top of this file).")
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                    help="repository root (default: the one holding this script)")
    args = ap.parse_args(argv)
    root = os.path.abspath(args.root)
    checker = Checker(root)
    if not checker.targets:
        print(f"check_layers: no targets found in {root}/{{solver,driver}}/**/CMakeLists.txt")
        return 1
    violations, n_files, n_includes = checker.run()
    for w in checker.warnings:
        print(f"warning: {w}", file=sys.stderr)
    for _, _, msg in sorted(set(violations)):
        print(msg)
    if violations:
        print(f"check_layers: {len(set(violations))} violation(s)")
        return 1
    print(f"check_layers: OK, {len(checker.targets)} targets, {n_files} files, "
          f"{n_includes} project includes, no wrong-way include or unused link")
    return 0


if __name__ == "__main__":
    sys.exit(main())
