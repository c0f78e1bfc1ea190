#!/usr/bin/env bash
# The contact sheets of the README's "Characters nobody rigged for us": run from the repository root.
set -e
export PATH="$PWD/.venv/bin:$PATH"
D=../shared/data; T=/tmp/sheets17; rm -rf $T; mkdir -p $T
# Xbot (Mixamo) playing a Bandai dataset-2 walk and an iClone (CMU 005_01) walk
rigedit retarget $D/bvh-library/bandai-2/dataset-2_walk_active_001.bvh --to $D/threejs-characters/Xbot.glb --name bandai2_walk -o $T/xbot_b2.glb
rigedit render bandai2_walk --rig $T/xbot_b2.glb -o $T/xbot_b2_side.gif --fps 4 --size 214x320 --view side -q
rigedit render bandai2_walk --rig $T/xbot_b2.glb -o $T/xbot_b2_35.gif --fps 4 --size 214x320 --angle 35 -q
rigedit retarget $D/bvh-library/cmu-iclone/005_01.bvh --to $D/threejs-characters/Xbot.glb --name iclone_walk -o $T/xbot_ic.glb
rigedit render iclone_walk --rig $T/xbot_ic.glb -o $T/xbot_ic_side.gif --fps 2 --size 214x320 --view side -q
rigedit render iclone_walk --rig $T/xbot_ic.glb -o $T/xbot_ic_35.gif --fps 2 --size 214x320 --angle 35 -q
python docs/make_sheet.py docs/retarget_xbot.png $T/xbot_b2_side.gif $T/xbot_b2_35.gif $T/xbot_ic_side.gif $T/xbot_ic_35.gif
# the horse's mesh (its skeleton ignored) auto-rigged as a quadruped, walking
rigedit autorig $D/quaternius-farm-animals/Horse.gltf --template quadruped -o $T/horse
rigedit render walk --rig $T/horse -o $T/horse_side.gif --fps 6 --size 280x210 --view side -q
rigedit render walk --rig $T/horse -o $T/horse_35.gif --fps 6 --size 280x210 --angle 35 -q
python docs/make_sheet.py docs/autorig_horse_walk.png $T/horse_side.gif $T/horse_35.gif
# the multi-part robot auto-rigged as a humanoid, waving
rigedit autorig $D/threejs-characters/RobotExpressive.glb --template humanoid -o $T/robot
rigedit render wave --rig $T/robot -o $T/robot_front.gif --fps 6 --size 214x320 --view front -q
rigedit render wave --rig $T/robot -o $T/robot_35.gif --fps 6 --size 214x320 --angle 35 -q
python docs/make_sheet.py docs/autorig_robot_wave.png $T/robot_front.gif $T/robot_35.gif
