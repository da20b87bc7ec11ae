"""Imports BVH files with Blender's own importer and writes every bone's head, every frame.

Run headless:

    blender -b --factory-startup --python import_bvh.py -- FILE.bvh OUT.json [FILE OUT ...]

Several FILE OUT pairs share one Blender launch. Each file is imported as an animator would
(File > Import > Motion Capture: forward -Z, up Y, scale 1, native rotation order, first
frame 1), each frame evaluated with `scene.frame_set`, and each bone's head taken in world
space and turned back into the file's axes: Blender (x, y, z) = BVH (x, -z, y). Each file is
imported a second time with quaternion rotations, whose bone heads differ from the native
import's only by Blender's single-precision rounding. OUT holds {"file", "bones": [name...],
"frames": [[[x, y, z] per bone] per frame], "frames_quaternion": ...} in the file's unit.

The BVH importer of Debian's Blender 3.4 opens files with mode 'rU', which Python 3.11
refuses: `open` is wrapped to drop the 'U'.
"""

import builtins
import json
import sys
import time

import bpy

_open = builtins.open


def _open_without_u(file, mode="r", *args, **kwargs):
    if isinstance(mode, str) and "U" in mode:
        mode = mode.replace("U", "") or "r"
    return _open(file, mode, *args, **kwargs)


builtins.open = _open_without_u


def frame_count(path):
    """The `Frames:` count of a BVH file."""
    with _open(path, "r") as f:
        for line in f:
            words = line.split()
            if words[:1] == ["Frames:"]:
                return int(words[1])
    raise ValueError(f"{path}: no 'Frames:' line")


def clear_scene():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for arm in list(bpy.data.armatures):
        bpy.data.armatures.remove(arm)
    for action in list(bpy.data.actions):
        bpy.data.actions.remove(action)


def heads(path, rotate_mode):
    """Every bone's head on every frame of `path` imported with `rotate_mode`."""
    clear_scene()
    result = bpy.ops.import_anim.bvh(
        filepath=path,
        target="ARMATURE",
        global_scale=1.0,
        frame_start=1,
        use_fps_scale=False,
        update_scene_fps=False,
        update_scene_duration=False,
        use_cyclic=False,
        rotate_mode=rotate_mode,
        axis_forward="-Z",
        axis_up="Y",
    )
    if result != {"FINISHED"}:
        raise RuntimeError(f"{path}: import returned {result}")
    arms = [ob for ob in bpy.data.objects if ob.type == "ARMATURE"]
    if len(arms) != 1:
        raise RuntimeError(f"{path}: {len(arms)} armatures imported")
    arm = arms[0]
    scene = bpy.context.scene
    bones = [pb.name for pb in arm.pose.bones]
    frames = []
    for f in range(frame_count(path)):
        scene.frame_set(1 + f)
        world = arm.matrix_world
        row = []
        for pb in arm.pose.bones:
            h = world @ pb.head
            # Blender (x, y, z) = BVH (x, -z, y).
            row.append([h.x, h.z, -h.y])
        frames.append(row)
    return bones, frames


def import_one(path, out):
    started = time.monotonic()
    bones, frames = heads(path, "NATIVE")
    # The same file with quaternion rotations: where Blender's two readings differ is its own
    # single-precision noise for this file.
    quaternion_bones, quaternion_frames = heads(path, "QUATERNION")
    if quaternion_bones != bones:
        raise RuntimeError(f"{path}: the quaternion import made other bones")
    with _open(out, "w") as f:
        json.dump(
            {
                "file": path,
                "bones": bones,
                "frames": frames,
                "frames_quaternion": quaternion_frames,
            },
            f,
        )
    print(
        f"kinergy-blender: {path}: {len(bones)} bones, {len(frames)} frames, "
        f"{time.monotonic() - started:.2f} s",
        file=sys.stderr,
    )


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    if not argv or len(argv) % 2:
        print("usage: blender -b --factory-startup --python import_bvh.py -- FILE OUT.json ...",
              file=sys.stderr)
        sys.exit(2)
    try:
        for path, out in zip(argv[::2], argv[1::2]):
            import_one(path, out)
    except Exception as e:  # the test reads the exit status; Blender's own is 0
        import traceback

        traceback.print_exc()
        print(f"kinergy-blender: failed: {e}", file=sys.stderr)
        sys.stdout.flush()
        sys.stderr.flush()
        import os

        os._exit(1)


main()
