"""Counts, per replayed reach in OUT (tools/speed-jumps.sh), the speed jumps of the capture and
of the synthesis (a frame-to-frame change > 0.25 m/s and > 4x the median change), whether it
reached, and its first-frame speed against the capture's."""
import csv, sys, glob, json, statistics, os
out = sys.argv[1]
def jumps(v):
    d=[abs(b-a) for a,b in zip(v,v[1:])]
    if not d: return 0
    t=max(0.25, 4*statistics.median(d))
    return sum(1 for x in d if x>t)
def pearson(a,b):
    ma,mb=statistics.fmean(a),statistics.fmean(b)
    num=sum((x-ma)*(y-mb) for x,y in zip(a,b))
    den=(sum((x-ma)**2 for x in a)*sum((y-mb)**2 for y in b))**0.5
    return num/den if den>0 else 0.0
n=extra=stalled=fast=far=0
corr=[]
for f in sorted(glob.glob(out+'/*.csv')):
    rows=list(csv.DictReader(open(f)))
    clips={}
    for r in rows: clips.setdefault(r['clip'],[]).append(float(r['speed_m_s']))
    names=list(clips)
    cap=[c for c in names if c.endswith('.cap')][0]; syn=[c for c in names if c.endswith('.syn')][0]
    L=min(len(clips[cap]),len(clips[syn]))
    jc, js = jumps(clips[cap][:L]), jumps(clips[syn][:L])
    j=json.load(open(f[:-4]+'.json')) if os.path.getsize(f[:-4]+'.json')>0 else {}
    st=j.get('stop','?')
    n+=1; extra+= js>jc; stalled+= st!='reached'
    d0=clips[syn][0]-clips[cap][0]; fast+= abs(d0)>0.3
    far+= j.get('final_error_m',1.0)>0.01
    corr.append(pearson(clips[cap][:L],clips[syn][:L]))
    if js>jc or st!='reached' or abs(d0)>0.3: print(os.path.basename(f), 'jumps cap/syn', jc, js, 'stop', st, 'r %.2f'%corr[-1], 'err_mm %.1f'%(1e3*j.get('final_error_m',0)), 'v0 cap/syn %.2f %.2f'%(clips[cap][0],clips[syn][0]))
print(f'{n} reaches: {extra} with extra jumps, {stalled} not reached ({far} end >1 cm from the target), {fast} start >0.3 m/s off; speed correlation with the capture mean {statistics.fmean(corr):.2f}, min {min(corr):.2f}')
