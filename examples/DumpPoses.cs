// A pose dump (docs/pose-dump.md) of what Unity plays: an animation clip sampled on a model's instance by
// `AnimationClip.SampleAnimation` at every frame, each transform's `localToWorldMatrix` written. UNTESTED: no Unity
// runs in bonescope's CI; it is kept short so that it can be checked by eye.
//
//   1. Put this file in an `Editor` folder of the project.
//   2. Drag the imported model (FBX or glTF) into a scene and select its instance (its root).
//   3. Tools > bonescope > Dump poses, and save `NAME.dump.json`.
//   4. bonescope fit FILE NAME.dump.json
//
// The clip is the first the instance's Animator or Animation plays. Unity is left-handed: its FBX importer and
// glTFast negate X on import, and this script negates it again on both sides of every matrix (M' = S·M·S, S =
// diag(-1, 1, 1)), so that the dump is in the file's right-handed axes, Y up, metres (the FBX importer's "Convert
// Units", on by default). Every transform under the root is a bone; Unity lets two share a name, a dump does not.

using System.Collections.Generic;
using System.Globalization;
using System.IO;
using System.Linq;
using System.Text;
using UnityEditor;
using UnityEngine;

public static class DumpPoses
{
    [MenuItem("Tools/bonescope/Dump poses")]
    static void Dump()
    {
        var root = Selection.activeGameObject;
        var clip = root == null ? null : AnimationUtility.GetAnimationClips(root).FirstOrDefault();
        if (clip == null)
        {
            Debug.LogError("Select a model's instance that plays an animation clip.");
            return;
        }
        var path = EditorUtility.SaveFilePanel("Pose dump", "", clip.name + ".dump.json", "json");
        if (string.IsNullOrEmpty(path)) return;

        // Parents before children, as GetComponentsInChildren visits them.
        var bones = root.GetComponentsInChildren<Transform>(true);
        var json = new StringBuilder();
        json.Append("{\"format\": \"bonescope-pose-dump\", \"version\": 1, \"space\": \"world\", ");
        json.Append("\"order\": \"column-major\", \"unit\": \"m\", \"up\": \"y\", ");
        json.Append($"\"clip\": {Quote(clip.name)}, \"source\": {Quote("Unity " + Application.unityVersion)},\n");
        json.Append("\"bones\": [");
        json.Append(string.Join(", ", bones.Select(b =>
            $"{{\"name\": {Quote(b.name)}, \"parent\": {(b == root.transform ? "null" : Quote(b.parent.name))}}}")));
        json.Append("],\n\"frames\": [");

        // Sampling moves the instance: undone once the dump is written.
        Undo.RegisterFullObjectHierarchyUndo(root, "Dump poses");
        var frames = Mathf.RoundToInt(clip.length * clip.frameRate);
        for (var frame = 0; frame <= frames; frame++)
        {
            var time = frame / clip.frameRate;
            clip.SampleAnimation(root, time);
            var matrices = bones.Select(b => ColumnMajorMirrored(b.localToWorldMatrix));
            json.Append(frame == 0 ? "\n" : ",\n");
            json.Append($"{{\"time\": {Number(time)}, \"matrices\": [{string.Join(", ", matrices)}]}}");
        }
        json.Append("\n]}\n");
        Undo.PerformUndo();
        File.WriteAllText(path, json.ToString());
        Debug.Log($"Pose dump of {bones.Length} transforms, {frames + 1} frames: {path}");
    }

    // The 16 numbers of S·m·S (S negates X), column after column.
    static string ColumnMajorMirrored(Matrix4x4 m)
    {
        var numbers = new List<string>();
        for (var column = 0; column < 4; column++)
            for (var row = 0; row < 4; row++)
                numbers.Add(Number(((row == 0) != (column == 0) ? -1f : 1f) * m[row, column]));
        return "[" + string.Join(",", numbers) + "]";
    }

    // Round-trip precision, whatever the machine's culture.
    static string Number(float x) => x.ToString("R", CultureInfo.InvariantCulture);

    static string Quote(string s) => "\"" + s.Replace("\\", "\\\\").Replace("\"", "\\\"") + "\"";
}
