#!/usr/bin/env bash
# Rebuilds the shipped vocabulary (vocab/default.pmvoc) reproducibly, as vocab/README.md describes:
#   scripts/build_vocabulary.sh [OUT]        (PATROLMAP_BIN: the binary, build/tools/patrolmap unless set)
# Installs the Debian packages whose photographs it trains on, simulates two training flights through
# villages that evaluation never uses, and runs `patrolmap vocab build` over both.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/vocab/default.pmvoc}"
bin="${PATROLMAP_BIN:-$root/build/tools/patrolmap}"
work="${TMPDIR:-/tmp}/patrolmap_vocabulary"
"$root/scripts/install_deps.sh" mate-backgrounds lomiri-wallpapers-16.04 opencv-doc
mkdir -p "$work"
# Only the frames the vocabulary is trained on are rendered: every 15th of the 30 Hz flights.
for flight in inner-loop:101 l-shape:102; do
  route=${flight%:*} seed=${flight#*:}
  [[ -f "$work/$route-$seed-every-15/cam0/data.csv" ]] || "$bin" --quiet simulate --route "$route" --seed "$seed" \
    --frame-step 15 --out "$work/$route-$seed-every-15"
done

# Photographs (vocab/README.md credits each): nature photographs of MATE's backgrounds, the photographs
# of Ubuntu's 16.04 wallpaper contest, and the photographs among OpenCV's sample data. The image pairs
# that evaluation uses (aero, graf, leuven, aloe) are left out.
mate=/usr/share/backgrounds/mate/nature
photos=(
  "$mate"/{Aqua,Blinds,Dune,FreshFlower,Garden,GreenMeadow,LadyBird,RainDrops,Storm,TwoWings,Wood,YellowFlower}.jpg
  /usr/share/backgrounds/{Bridge_by_Sander_Klootwijk,Dragonfly_by_Bolly,umang_by_Abhishek_Mudgal}.jpg
  /usr/share/backgrounds/{Picture_0B_by_freespace,Picture_1A_by_freespace,Wine_by_Jakkub_Mede}.jpg
  /usr/share/backgrounds/{aitzgorri,friends,life,picosdeeuropa,sunset}_by_Aitzol_Berasategi.jpg
  /usr/share/backgrounds/{free,greentock}_by_Peter_Nerlich.jpg
  /usr/share/backgrounds/seeding_by_Clements_Engelhardt.jpg
)
opencv=/usr/share/doc/opencv-doc/examples/data
for name in building.jpg home.jpg box.png box_in_scene.png stuff.jpg fruits.jpg baboon.jpg messi5.jpg \
    butterfly.jpg orange.jpg apple.jpg basketball1.png squirrel_cls.jpg HappyFish.jpg licenseplate_motion.jpg \
    rubberwhale1.png smarties.png; do
  photos+=("$opencv/$name")
done
missing=()
for photo in "${photos[@]}"; do [[ -f "$photo" ]] || missing+=("$photo"); done
if ((${#missing[@]})); then
  echo "build_vocabulary.sh: training photographs missing (their Debian package changed?): ${missing[*]}" >&2
  exit 1
fi
"$bin" vocab build "$work/inner-loop-101-every-15" "$work/l-shape-102-every-15" "${photos[@]}" -k 10 -L 4 --every 1 \
  --seed 1 --out "$out"
