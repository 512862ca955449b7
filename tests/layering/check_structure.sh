#!/usr/bin/env bash
# Fails when the product code grows knots a reader cannot hold at once:
#   - a file under algo/, firmware/, hal/ or sim/ over 600 lines: split it by what it does;
#   - a class whose member functions are defined in more than two .cc files: its state is shared
#     by too many pieces, each of which wants to be a class of its own. SIMD twins count like
#     any file, so a kernel's twins stay free functions that the class calls.
# A definition is a line of a .cc file starting at its first column with `Class::Method(` (or
# `Outer::Inner::Method(`) after nothing but its return type: the form clang-format gives every
# definition.
#   tests/layering/check_structure.sh ROOT
# Prints one line per violation and exits 1 if there is any.
set -u
root=${1:?usage: check_structure.sh ROOT}
max_lines=600
max_files=2
violations=0

dirs=()
for top in algo firmware hal sim; do
  [ -d "$root/$top" ] && dirs+=("$root/$top")
done
[ ${#dirs[@]} -gt 0 ] || {
  echo "structure: no algo/, firmware/, hal/ or sim/ under $root"
  exit 1
}

while IFS= read -r -d '' file; do
  lines=$(wc -l <"$file")
  if [ "$lines" -gt "$max_lines" ]; then
    echo "structure: ${file#"$root"/} has $lines lines (at most $max_lines)"
    violations=$((violations + 1))
  fi
done < <(find "${dirs[@]}" -type f -print0 | sort -z)

# Class, then the files defining its members, one pair a line.
while IFS= read -r hit; do
  echo "structure: $hit"
  violations=$((violations + 1))
done < <(find "${dirs[@]}" -type f -name '*.cc' -print0 | sort -z | xargs -0 -r awk -v root="$root/" -v most="$max_files" '
  /^[[:space:]#\/]/ || /^(return|case|else|if|for|while|using|namespace)[^A-Za-z0-9_]/ { next }
  match($0, /([A-Za-z_][A-Za-z0-9_]*::)+(~?[A-Za-z_][A-Za-z0-9_]*|operator[^(]*)[[:space:]]*\(/) {
    if (substr($0, 1, RSTART - 1) ~ /[=({]/) next  # a call, not a definition
    name = substr($0, RSTART, RLENGTH)
    sub(/::[^:]*$/, "", name)          # drop the member: the class (with its outer classes)
    sub(/^(lb|std)::/, "", name)       # the namespace, when written out
    if (name == "lb" || name == "std") next
    file = substr(FILENAME, length(root) + 1)
    if (!((name, file) in seen)) {
      seen[name, file] = 1
      count[name]++
      files[name] = files[name] " " file
    }
  }
  END {
    for (c in count)
      if (count[c] > most)
        printf "class %s has member functions defined in %d .cc files (at most %d):%s\n", c,
               count[c], most, files[c]
  }')

[ "$violations" -eq 0 ]
