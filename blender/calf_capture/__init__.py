"""calf capture: renders calf capture sets (format/CAPTURE.md) and ground truth of the open scene
with Cycles. Install the folder (zipped) in Blender's Preferences > Add-ons, or run headless:

    blender -b scene.blend -P blender/calf_capture/cli.py -- --out DIR [options]

docs/BLENDER.md describes both and what the add-on converts.
"""

bl_info = {
    "name": "calf capture",
    "author": "the calf authors",
    "version": (1, 0, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Output > calf capture",
    "description": "Render calf light-field capture sets and ground truth with Cycles",
    "category": "Render",
}

try:
    import bpy
except ImportError:  # imported outside Blender (the pure-Python parts are usable alone)
    bpy = None

if bpy is not None:
    from . import capture

    class CalfCaptureSettings(bpy.types.PropertyGroup):
        out: bpy.props.StringProperty(name="Output folder", subtype="DIR_PATH",
                                      default="//calf_capture/")
        viewpoints: bpy.props.EnumProperty(
            name="Viewpoints", default="COLLECTION",
            items=[("COLLECTION", "Collection", "The empties of a collection"),
                   ("RIG", "Rig string", "A calf rig string, as calf-capture --rig")])
        collection: bpy.props.PointerProperty(name="Collection", type=bpy.types.Collection)
        rig: bpy.props.StringProperty(name="Rig", default="box:0,1.6,0,0.3,0.2,0.3")
        volume_object: bpy.props.PointerProperty(name="Volume box", type=bpy.types.Object)
        face_size: bpy.props.IntProperty(name="Face size", default=64, min=1, max=16384)
        samples: bpy.props.IntProperty(name="Samples", default=64, min=1)
        seed: bpy.props.IntProperty(name="Seed", default=0)
        adaptive_threshold: bpy.props.FloatProperty(
            name="Adaptive threshold", default=capture.CAPTURE_ADAPTIVE_THRESHOLD, min=0.0,
            max=1.0, precision=4,
            description="Cycles' adaptive sampling noise threshold; 0 = off (every pixel gets "
            "every sample)")

    class CALF_OT_capture(bpy.types.Operator):
        """Render a calf capture set of this scene (six faces per viewpoint and frame)"""

        bl_idname = "calf.capture"
        bl_label = "Render calf capture set"

        def execute(self, context):
            s = context.scene.calf_capture
            o = capture.CaptureOptions()
            o.out = bpy.path.abspath(s.out)
            if s.viewpoints == "RIG":
                o.rig = s.rig
            else:
                o.collection = s.collection.name if s.collection else ""
            o.volume_object = s.volume_object.name if s.volume_object else ""
            o.face_size, o.samples, o.seed = s.face_size, s.samples, s.seed
            o.adaptive_threshold = s.adaptive_threshold
            try:
                m = capture.capture_set(context.scene, o)
            except capture.CaptureError as e:
                self.report({"ERROR"}, str(e))
                return {"CANCELLED"}
            self.report({"INFO"}, "calf capture: %d viewpoints x %d frames in %s" %
                        (len(m["viewpoints"]), m["frame_count"], o.out))
            return {"FINISHED"}

    class CALF_PT_capture(bpy.types.Panel):
        bl_label = "calf capture"
        bl_space_type = "PROPERTIES"
        bl_region_type = "WINDOW"
        bl_context = "output"

        def draw(self, context):
            s = context.scene.calf_capture
            col = self.layout.column()
            col.prop(s, "out")
            col.prop(s, "viewpoints")
            col.prop(s, "collection" if s.viewpoints == "COLLECTION" else "rig")
            col.prop(s, "volume_object")
            col.prop(s, "face_size")
            col.prop(s, "samples")
            col.prop(s, "seed")
            col.prop(s, "adaptive_threshold")
            col.operator(CALF_OT_capture.bl_idname, icon="RENDER_ANIMATION")

    _classes = (CalfCaptureSettings, CALF_OT_capture, CALF_PT_capture)

    def register():
        for c in _classes:
            bpy.utils.register_class(c)
        bpy.types.Scene.calf_capture = bpy.props.PointerProperty(type=CalfCaptureSettings)

    def unregister():
        del bpy.types.Scene.calf_capture
        for c in reversed(_classes):
            bpy.utils.unregister_class(c)
