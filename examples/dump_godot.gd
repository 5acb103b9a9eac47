# A pose dump (docs/pose-dump.md) of what Godot 3 plays: a glTF file imported by Godot's own importer, its
# animation played by the AnimationPlayer, every Skeleton's node and bones' global poses written at every key time.
# Godot 3.2 (Debian's `godot3`), run in a project folder that holds the file (its editor imports it first, which
# needs a display: Xvfb where there is none):
#
#   cp FILE.glb PROJECT/ && echo 'config_version=4' > PROJECT/project.godot
#   printf '[remap]\nimporter="scene"\ntype="PackedScene"\n[params]\nanimation/fps=120\nanimation/optimizer/enabled=false\n' \
#     > PROJECT/FILE.glb.import                                        # see below
#   xvfb-run -a godot3 --path PROJECT --editor --quit                  # imports FILE.glb
#   xvfb-run -a godot3 --path PROJECT --no-window -s /abs/examples/dump_godot.gd FILE.glb OUT.dump.json [CLIP]
#   bonescope fit FILE.glb OUT.dump.json
#
# FILE.glb is relative to the project; OUT.dump.json an absolute path. CLIP is the animation's name (default: the
# first). A bone's matrix is `skeleton.global_transform * skeleton.get_bone_global_pose(bone)`, column-major (a
# Transform's basis columns, then its origin), in metres, Y up as glTF. Godot's importer resamples every track at
# its `animation/fps` (15 by default) and thins the keys with its optimizer (5 cm off by default): the `.import`
# file above asks for 120 fps and no optimizer, else the fit measures the import as well. It renames bones it finds
# no valid node name (`thigh.l` becomes `thighl`), which then pair with none of the source's.

extends SceneTree

var scene
var out_path
var clip_name


func _initialize():
	var args = []
	for arg in OS.get_cmdline_args():
		# The engine's own options and this script's path come first; the file is the first `.glb`/`.gltf`.
		if args.empty() and not (arg.ends_with(".glb") or arg.ends_with(".gltf")):
			continue
		args.append(arg)
	if args.size() < 2:
		printerr("usage: godot3 --path PROJECT --no-window -s dump_godot.gd FILE.glb OUT.dump.json [CLIP]")
		quit(2)
		return
	out_path = args[1]
	clip_name = args[2] if args.size() > 2 else null
	scene = load("res://" + args[0]).instance()
	root.add_child(scene)


# The dump is made on the first frame, once the scene is in the tree.
func _idle(_delta):
	if scene == null:
		return true
	var player = find_first(scene, "AnimationPlayer")
	var names = player.get_animation_list()
	var clip = clip_name if clip_name != null else names[0]
	if not player.has_animation(clip):
		printerr("no animation %s: %s" % [clip, names])
		quit(2)
		return true
	var skeletons = []
	find_all(scene, "Skeleton", skeletons)
	var bones = bones_of(skeletons)
	player.play(clip)
	var frames = []
	for time in key_times(player.get_animation(clip)):
		player.seek(time, true)
		var matrices = []
		for bone in bones:
			matrices.append(column_major(world(bone)))
		frames.append({"time": time, "matrices": matrices})
	var named = []
	for bone in bones:
		named.append({"name": bone.name, "parent": bone.parent})
	var dump = {
		"version": 1, "space": "world", "order": "column-major", "unit": "m", "up": "y", "clip": clip,
		"source": "Godot %s glTF importer + AnimationPlayer" % Engine.get_version_info().string,
		"bones": named, "frames": frames,
	}
	var file = File.new()
	file.open(out_path, File.WRITE)
	# `format` first, where a reader looks for it (to_json sorts the keys).
	file.store_string('{"format": "bonescope-pose-dump", ' + to_json(dump).substr(1))
	file.close()
	quit(0)
	return true


# Each skeleton node as a root and its bones under it: {name, parent, skeleton, bone (-1 for the node)}.
func bones_of(skeletons):
	var bones = []
	for skeleton in skeletons:
		bones.append({"name": skeleton.name, "parent": null, "skeleton": skeleton, "bone": -1})
		for bone in range(skeleton.get_bone_count()):
			var parent = skeleton.get_bone_parent(bone)
			var parent_name = skeleton.get_bone_name(parent) if parent >= 0 else skeleton.name
			bones.append({"name": skeleton.get_bone_name(bone), "parent": parent_name, "skeleton": skeleton, "bone": bone})
	return bones


func world(bone):
	var skeleton = bone.skeleton
	if bone.bone < 0:
		return skeleton.global_transform
	return skeleton.global_transform * skeleton.get_bone_global_pose(bone.bone)


func column_major(t):
	var b = t.basis
	return [b.x.x, b.x.y, b.x.z, 0, b.y.x, b.y.y, b.y.z, 0, b.z.x, b.z.y, b.z.z, 0, t.origin.x, t.origin.y, t.origin.z, 1]


# Every key time of every track, in order.
func key_times(animation):
	var seen = {}
	for track in range(animation.get_track_count()):
		for key in range(animation.track_get_key_count(track)):
			seen[animation.track_get_key_time(track, key)] = true
	var times = seen.keys()
	times.sort()
	return times


func find_first(node, type):
	if node.is_class(type):
		return node
	for child in node.get_children():
		var found = find_first(child, type)
		if found != null:
			return found
	return null


func find_all(node, type, into):
	if node.is_class(type):
		into.append(node)
	for child in node.get_children():
		find_all(child, type, into)
