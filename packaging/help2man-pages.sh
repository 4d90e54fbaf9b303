#!/bin/sh
# Man pages generated with help2man from the same text as --help (issue 24).
# usage: help2man-pages.sh EXE OUTPUT_DIR VERSION "NAME LINE" [SEE_ALSO...]
#   writes OUTPUT_DIR/PROG.1 (PROG = basename of EXE); when `EXE --help` lists commands under
#   "commands:" (navsim), also OUTPUT_DIR/PROG-COMMAND.1 for each, from `EXE COMMAND --help`.
set -eu
exe=$1
out=$2
version=$3
name=$4
shift 4
prog=$(basename "$exe")
command -v help2man >/dev/null 2>&1 || { echo "help2man-pages.sh: help2man is not installed (Debian: help2man)" >&2; exit 1; }
mkdir -p "$out/wrap"
rm -f "$out/$prog.1" "$out/$prog"-*.1

# help2man makes the SYNOPSIS from "Usage: A" and "  or: B" lines: the wrappers it runs capitalise
# the program's "usage:", join the usage's indented continuation lines into one line per form
# (a continuation starting with the program's name is another form) and pass the rest as it is.
wrap() { # wrap FILE ARGS...: a script running EXE ARGS
  f=$1
  shift
  cat > "$f" <<WRAP
#!/bin/sh
"$exe" $* "\$@" | awk -v prog="$prog" '
  NR == 1 && /^usage:/ { sub(/^usage:/, "Usage:"); u = \$0; inu = 1; next }
  inu && /^ +[^ ]/ {
    sub(/^ +/, "")
    if (index(\$0, prog " ") == 1) { print u; u = "  or: " \$0 } else u = u " " \$0
    next
  }
  inu { print u; inu = 0 }
  { print }
  END { if (inu) print u }'
WRAP
  chmod +x "$f"
}

# The command list: the lines "  NAME ..." under "commands:" of --help.
cmds=$("$exe" --help | sed -n '/^commands:/,/^$/p' | sed -n 's/^  \([a-z][a-z0-9-]*\) .*/\1/p')
see_also=""
for s in "$@"; do see_also="$see_also${see_also:+,
}.BR $s (1)"; done
for c in $cmds; do see_also="$see_also${see_also:+,
}.BR $prog-$c (1)"; done
printf '[SEE ALSO]\n%s\n' "$see_also" > "$out/wrap/see-also.h2m"
wrap "$out/wrap/$prog"
help2man --no-info --no-discard-stderr --version-string="$version" --section=1 --name="$name" \
  --include="$out/wrap/see-also.h2m" --output="$out/$prog.1" "$out/wrap/$prog"
for c in $cmds; do
  # NAME line: the command's line in the list, without its arguments.
  desc=$("$exe" --help | sed -n '/^commands:/,/^$/p' | sed -n "s/^  $c  *[A-Z][A-Z._|]* \{2,\}\(.*\)/\1/p; s/^  $c \{2,\}\([^ ].*\)/\1/p" | head -n 1)
  [ -n "$desc" ] || desc="$prog $c"
  w="$out/wrap/$prog-$c"
  wrap "$w" "$c"
  printf '[SEE ALSO]\n.BR %s (1)\n' "$prog" > "$out/wrap/see-also-$c.h2m"
  help2man --no-info --no-discard-stderr --version-string="$version" --section=1 --name="$desc" \
    --include="$out/wrap/see-also-$c.h2m" --output="$out/$prog-$c.1" "$w"
done
# Debian ships manual pages compressed (gzip -n: no name or time stamp, the same bytes each time).
for f in "$out/$prog.1" "$out/$prog"-*.1; do
  if [ -f "$f" ]; then gzip -9nc "$f" > "$f.gz"; fi
done
