"""A small ASCII FBX 7.4 file written by the tests (no FBX file needed): a skinned quad with a
blend shape and its weight curve, optionally a textured material."""

__all__ = ["mini_fbx"]

_KTIME = 46186158000     # FBX time units per second


def mini_fbx(weight_keys, texture=None):
    """A small ASCII FBX 7.4 file written here: a 1 m quad (centimetres, Y up) bound to one
    bone at its bind pose, a blend shape "Raise" lifting two corners 0.5 m along +Z with a
    default DeformPercent of 25 and a linear DeformPercent curve of ``weight_keys``
    ((seconds, percent) pairs), and a material whose diffuse texture is ``texture``."""
    times = ",".join(str(int(round(t * _KTIME))) for t, _ in weight_keys)
    vals = ",".join(f"{v:g}" for _, v in weight_keys)
    n = len(weight_keys)
    material = "" if texture is None else f'''
	Material: 1400, "Material::Skin", "" {{
		Properties70:  {{
			P: "DiffuseColor", "Color", "", "A",0.8,0.2,0.2
		}}
	}}
	Texture: 1500, "Texture::Base", "" {{
		FileName: "{texture}"
		RelativeFilename: "{texture}"
	}}'''
    links = "" if texture is None else '''
	C: "OO",1400,200
	C: "OP",1500,1400, "DiffuseColor"'''
    return f'''; FBX 7.4.0 project file
FBXHeaderExtension:  {{
	FBXHeaderVersion: 1003
	FBXVersion: 7400
}}
GlobalSettings:  {{
	Version: 1000
	Properties70:  {{
		P: "UpAxis", "int", "Integer", "",1
		P: "UpAxisSign", "int", "Integer", "",1
		P: "FrontAxis", "int", "Integer", "",2
		P: "FrontAxisSign", "int", "Integer", "",1
		P: "CoordAxis", "int", "Integer", "",0
		P: "CoordAxisSign", "int", "Integer", "",1
		P: "UnitScaleFactor", "double", "Number", "",1
		P: "TimeMode", "enum", "", "",11
	}}
}}
Objects:  {{{material}
	Geometry: 100, "Geometry::Quad", "Mesh" {{
		Vertices: *12 {{
			a: 0,0,0,100,0,0,100,100,0,0,100,0
		}}
		PolygonVertexIndex: *4 {{
			a: 0,1,2,-4
		}}
		GeometryVersion: 124
	}}
	Model: 200, "Model::Quad", "Mesh" {{
		Version: 232
	}}
	NodeAttribute: 300, "NodeAttribute::Bone", "LimbNode" {{
		TypeFlags: "Skeleton"
	}}
	Model: 400, "Model::Bone", "LimbNode" {{
		Version: 232
	}}
	Deformer: 500, "Deformer::Skin", "Skin" {{
		Version: 101
	}}
	Deformer: 600, "SubDeformer::Cluster", "Cluster" {{
		Version: 100
		Indexes: *4 {{
			a: 0,1,2,3
		}}
		Weights: *4 {{
			a: 1,1,1,1
		}}
		Transform: *16 {{
			a: 1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1
		}}
		TransformLink: *16 {{
			a: 1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1
		}}
	}}
	Geometry: 700, "Geometry::Raise", "Shape" {{
		Version: 100
		Indexes: *2 {{
			a: 2,3
		}}
		Vertices: *6 {{
			a: 0,0,50,0,0,50
		}}
	}}
	Deformer: 800, "Deformer::Blend", "BlendShape" {{
		Version: 100
	}}
	Deformer: 900, "SubDeformer::Raise", "BlendShapeChannel" {{
		Version: 100
		DeformPercent: 25
		FullWeights: *1 {{
			a: 100
		}}
	}}
	AnimationStack: 1000, "AnimStack::Take 001", "" {{
		Properties70:  {{
			P: "LocalStop", "KTime", "Time", "",{int(round(weight_keys[-1][0] * _KTIME))}
		}}
	}}
	AnimationLayer: 1100, "AnimLayer::BaseLayer", "" {{
	}}
	AnimationCurveNode: 1200, "AnimCurveNode::DeformPercent", "" {{
		Properties70:  {{
			P: "d|DeformPercent", "Number", "", "A",0
		}}
	}}
	AnimationCurve: 1300, "AnimCurve::", "" {{
		Default: 0
		KeyVer: 4009
		KeyTime: *{n} {{
			a: {times}
		}}
		KeyValueFloat: *{n} {{
			a: {vals}
		}}
		KeyAttrFlags: *1 {{
			a: 260
		}}
		KeyAttrDataFloat: *4 {{
			a: 0,0,218434821,0
		}}
		KeyAttrRefCount: *1 {{
			a: {n}
		}}
	}}
}}
Connections:  {{
	C: "OO",200,0
	C: "OO",400,0
	C: "OO",300,400
	C: "OO",100,200
	C: "OO",500,100
	C: "OO",600,500
	C: "OO",400,600
	C: "OO",800,100
	C: "OO",900,800
	C: "OO",700,900
	C: "OO",1100,1000
	C: "OO",1200,1100
	C: "OP",1200,900, "DeformPercent"
	C: "OP",1300,1200, "d|DeformPercent"{links}
}}
'''
