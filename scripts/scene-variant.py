#!/usr/bin/env python3
"""Writes a variant of a scene file with some material kinds made Lambert and some
object types dropped, for the measurements in BENCHMARKS.md ("What stays slow").

    scripts/scene-variant.py SCENE OUT MODE

MODE is a comma-separated list: material types to replace by a grey Lambert
(`dielectric`, `mirror`, ...) and `drop:TYPE` for object types to leave out
(`drop:polygon`), or `none`. Example:

    scripts/scene-variant.py scenes/glass.toml /tmp/g1.toml drop:polygon
    cargo run --release -p gpu-render-tools --bin bench -- /tmp/g1.toml --width 640 --height 360
"""
import tomllib, sys, json
src, dst, mode = sys.argv[1], sys.argv[2], sys.argv[3]
d = tomllib.load(open(src,'rb'))
def val(v):
    if isinstance(v, str): return json.dumps(v)
    if isinstance(v, bool): return 'true' if v else 'false'
    if isinstance(v, list): return '[' + ', '.join(val(x) for x in v) + ']'
    return repr(v)
out=[]
for key in ('render','camera','environment'):
    if key in d:
        out.append(f'[{key}]')
        for k,v in d[key].items(): out.append(f'{k} = {val(v)}')
for name, m in d.get('materials',{}).items():
    kinds = mode.split(',')
    if m['type'] in kinds:
        m = {'type':'lambert','albedo':0.5}
    out.append(f'[materials.{name}]')
    for k,v in m.items(): out.append(f'{k} = {val(v)}')
for l in d.get('lights',[]):
    out.append('[[lights]]')
    for k,v in l.items(): out.append(f'{k} = {val(v)}')
for o in d.get('objects',[]):
    if 'drop:'+o['type'] in mode: continue
    out.append('[[objects]]')
    for k,v in o.items(): out.append(f'{k} = {val(v)}')
open(dst,'w').write('\n'.join(out)+'\n')
