#!/bin/sh
# check_layers.sh ROOT [MAP]: check every #include of the C/C++ sources under ROOT and every
# target command of its CMake files against the layer map (default ROOT/tests/layers/layers.map;
# the format is described at its top). Prints one line per violation,
#   FILE:LINE: RULE: what was found
# and exits 1 when there is any, 2 when the map itself is wrong, 0 otherwise.
#
# Include rules: a file may include its own component's headers, the public headers of the
# components its component "uses", and anything of the components it is a "whitebox" of.
# Path rule: only the map's "paths" file finds the running executable ("/proc/self/exe") or reads
# the variables that relocate the shared data (NAV_SHARE_DIR, NAV_RESOURCES_DIR, NAVVIEW_MAP_DATA):
# resource and tool paths are resolved at run time by one function.
# CMake rule: a target command (target_*, set_target_properties, set_property(TARGET),
# add_dependencies, nav_warnings) may only change a target defined in the same folder; the
# folder that defines a target decides its settings.
set -u
export LC_ALL=C   # one sort order for the file list and so for the report
root="${1:?usage: check_layers.sh ROOT [MAP]}"
map="${2:-$root/tests/layers/layers.map}"
[ -d "$root" ] || { echo "check_layers: no folder $root" >&2; exit 2; }
[ -r "$map" ] || { echo "check_layers: cannot read the layer map $map" >&2; exit 2; }
map="$(cd "$(dirname "$map")" && pwd)/$(basename "$map")"
cd "$root" || exit 2

# Folders not scanned (the map's skip lines), as find -prune arguments.
prune=$(awk '$1 == "skip" { for (i = 2; i <= NF; i++) printf " -path ./%s -prune -o", $i }' "$map")
# shellcheck disable=SC2086
sources=$(find . $prune -type f \( -name '*.c' -o -name '*.h' -o -name '*.cpp' -o -name '*.cxx' \
  -o -name '*.hpp' -o -name '*.hxx' -o -name '*.cc' -o -name '*.h.in' \) -print | sed 's|^\./||' | sort)
# shellcheck disable=SC2086
cmakes=$(find . $prune -type f \( -name CMakeLists.txt -o -name '*.cmake' \) -print | sed 's|^\./||' | sort)

{ printf '%s\n' "$sources" | sed 's/^/S /'; printf '%s\n' "$cmakes" | sed 's/^/C /'; } | awk -v MAP="$map" '
function fail_map(msg) { print MAP ": " msg > "/dev/stderr"; maperr = 1 }
function viol(where, rule, what) { print where ": " rule ": " what; nviol++ }
function exists(p,   x, r) { r = (getline x < p); close(p); return r >= 0 }
function dirname(p) { return (p ~ /\//) ? substr(p, 1, match(p, /\/[^\/]*$/) - 1) : "." }
# a/./b/../c -> a/c; "" when the path leaves the tree.
function normpath(p,   n, a, i, out, k, stack) {
  n = split(p, a, "/"); k = 0
  for (i = 1; i <= n; i++) {
    if (a[i] == "" || a[i] == ".") continue
    if (a[i] == "..") { if (k == 0) return ""; k--; continue }
    stack[++k] = a[i]
  }
  out = ""; for (i = 1; i <= k; i++) out = out (i > 1 ? "/" : "") stack[i]
  return out
}
function under(p, q) { return p == q || substr(p, 1, length(q) + 1) == q "/" }
# Component of a path: the longest component path it lies under ("" if none).
function owner(p,   i, best, bl) {
  best = ""; bl = -1
  for (i = 1; i <= ncp; i++) if (under(p, cpath[i]) && length(cpath[i]) > bl) { best = cname[i]; bl = length(cpath[i]) }
  return best
}
function is_public(c, p,   i) {
  for (i = 1; i <= npub; i++) if (pubc[i] == c && under(p, pubp[i])) return 1
  return 0
}
# The file a #include names, as the compiler would find it: the includer folder first (quoted
# only), then the roots. A generated header is found by its template (name.in).
function resolve(f, name, quoted,   c, i) {
  if (quoted) { c = normpath(dirname(f) "/" name); if (c != "" && exists(c)) return c }
  for (i = 1; i <= nroot; i++) {
    c = normpath(root[i] "/" name)
    if (c != "" && exists(c)) return c
    if (c != "" && exists(c ".in")) return c ".in"
  }
  return ""
}
BEGIN {
  while ((getline line < MAP) > 0) {
    sub(/#.*/, "", line); n = split(line, w, /[ \t]+/)
    if (n == 0 || (n == 1 && w[1] == "")) continue
    if (w[1] == "") { for (i = 1; i < n; i++) w[i] = w[i + 1]; n-- }
    if (w[1] == "component") {
      if (n < 4 || w[3] !~ /^[0-9]+$/) { fail_map("component NAME RANK PATH... expected: " line); continue }
      if ((w[2] in rank) && rank[w[2]] != w[3]) fail_map("component " w[2] " has two ranks")
      rank[w[2]] = w[3] + 0
      for (i = 4; i <= n; i++) { ncp++; cname[ncp] = w[2]; cpath[ncp] = w[i] }
    } else if (w[1] == "public") {
      for (i = 3; i <= n; i++) { npub++; pubc[npub] = w[2]; pubp[npub] = w[i] }
    } else if (w[1] == "uses" || w[1] == "whitebox") {
      for (i = 3; i <= n; i++) { rel[w[1], w[2], w[i]] = 1; pend[++npend] = w[1] " " w[2] " " w[i] }
    } else if (w[1] == "paths") {
      pathsfile = w[2]
    } else if (w[1] == "root") {
      for (i = 2; i <= n; i++) root[++nroot] = w[i]
    } else if (w[1] != "skip") fail_map("unknown line: " line)
  }
  close(MAP)
  if (ncp == 0) fail_map("no component line")
  # The map itself may only point down: a dependency on an equal or higher rank is an error.
  for (i = 1; i <= npend; i++) {
    split(pend[i], w, " ")
    if (!(w[2] in rank) || !(w[3] in rank)) { fail_map(pend[i] ": unknown component"); continue }
    if (rank[w[3]] >= rank[w[2]]) fail_map(pend[i] ": " w[3] " (rank " rank[w[3]] ") is not below " w[2] " (rank " rank[w[2]] ")")
  }
  if (maperr) exit 2
}
$1 == "S" && NF == 2 {
  f = $2; c = owner(f)
  if (c == "") { viol(f ":1", "unmapped", "file in no component of the layer map (add its folder to the map)"); next }
  ln = 0
  while ((getline l < f) > 0) {
    ln++
    if (f != pathsfile && (index(l, "\"/proc/self/exe\"") || l ~ /getenv\("(NAV_SHARE_DIR|NAV_RESOURCES_DIR|NAVVIEW_MAP_DATA)"\)/))
      viol(f ":" ln, "path-resolution", "finds a resource or program path itself; call the path function of " (pathsfile == "" ? "the map (paths line)" : pathsfile))
    if (l !~ /^[ \t]*#[ \t]*include[ \t]*["<]/) continue
    q = (l ~ /^[ \t]*#[ \t]*include[ \t]*"/)
    name = l; sub(/^[ \t]*#[ \t]*include[ \t]*["<]/, "", name); sub(/[">].*/, "", name)
    r = resolve(f, name, q)
    if (r == "") continue
    oc = owner(r)
    if (oc == "" || oc == c) continue
    if (rel["whitebox", c, oc]) continue
    if (!is_public(oc, r))
      viol(f ":" ln, "private-header", c " includes " r ", a private header of " oc " (another component may include only the public headers of " oc ")")
    else if (!rel["uses", c, oc])
      viol(f ":" ln, (rank[oc] >= rank[c] ? "upward-include" : "undeclared-use"), c " (rank " rank[c] ") includes " r " of " oc " (rank " rank[oc] "), not among the components " c " uses")
  }
  close(f)
  next
}
$1 == "C" && NF == 2 { cm[++ncm] = $2 }
END {
  if (maperr) exit 2
  # CMake: where each target is defined (add_library / add_executable / add_custom_target and
  # helper functions whose first argument is the target they create), then every command that
  # changes a target.
  for (pass = 1; pass <= 2; pass++) {
    for (k = 1; k <= ncm; k++) {
      f = cm[k]; d = dirname(f); ln = 0; want = ""
      while ((getline l < f) > 0) {
        ln++; sub(/#.*/, "", l)
        while (l != "") {
          if (want != "") {
            # the first argument of a command that started on an earlier line
            if (match(l, /[^ \t()]+/)) { handle(pass, want, substr(l, RSTART, RLENGTH), f, d, wln); want = "" }
            break
          }
          if (!match(l, /[A-Za-z_][A-Za-z0-9_]*[ \t]*\(/)) break
          cmd = substr(l, RSTART, RLENGTH); sub(/[ \t]*\($/, "", cmd); cmd = tolower(cmd)
          l = substr(l, RSTART + RLENGTH)
          if (!(cmd in kind)) continue
          if (kind[cmd] == "target-keyword") {
            if (l ~ /^[ \t]*TARGET[ \t]*$/) { want = cmd; wln = ln; break }
            if (!match(l, /^[ \t]*TARGET[ \t]+/)) continue
            l = substr(l, RSTART + RLENGTH)
          }
          if (match(l, /^[ \t]*[^ \t()]+/)) { a = substr(l, RSTART, RLENGTH); gsub(/[ \t]/, "", a); handle(pass, cmd, a, f, d, ln) }
          else { want = cmd; wln = ln; break }
        }
      }
      close(f)
    }
  }
  exit (nviol > 0)
}
function handle(pass, cmd, t, f, d, ln) {
  if (t ~ /\$/ || t ~ /::/) return           # a variable or an imported target
  if (pass == 1) {
    if (kind[cmd] == "define" && !(t in tdir)) { tdir[t] = d; tfile[t] = f }
    return
  }
  if (kind[cmd] == "define") return
  if (!(t in tdir)) return                     # not a target of this tree (e.g. a Qt or VTK one)
  if (tdir[t] != d)
    viol(f ":" ln, "foreign-target", cmd "(" t ") changes a target defined in " tfile[t] " (only the folder that defines a target sets its sources, definitions, dependencies and properties)")
}
BEGIN {
  kind["add_library"] = kind["add_executable"] = kind["add_custom_target"] = "define"
  kind["nav_add_cmocka_test"] = kind["navview_add_test"] = "define"
  kind["target_compile_definitions"] = kind["target_compile_options"] = kind["target_include_directories"] = "edit"
  kind["target_link_libraries"] = kind["target_link_options"] = kind["target_sources"] = "edit"
  kind["target_compile_features"] = kind["target_precompile_headers"] = kind["target_link_directories"] = "edit"
  kind["set_target_properties"] = kind["add_dependencies"] = kind["nav_warnings"] = "edit"
  kind["set_property"] = "target-keyword"
}
'
